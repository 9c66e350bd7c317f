"""Linear modes of a cooperative plant at a state: see :mod:`coopctrl.integrators.modes`.

The modal analysis lives beside the integrators whose stable steps it predicts, below the closed
loop (which asks it for step limits and advice); this module keeps its public names here.
"""

from coopctrl.integrators.modes import ModalAnalysis, damping_ratio_of, holding_torque, linear_modes

__all__ = ["ModalAnalysis", "damping_ratio_of", "holding_torque", "linear_modes"]
