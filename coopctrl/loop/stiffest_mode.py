"""The stiffest mode of the plant at a state, named by the coordinate that moves most in it.

Used to explain why an error-controlled integrator's step collapsed (:class:`~coopctrl.errors.StepTooSmall`):
the linearization ``A = df/dx`` at the failing state (:func:`coopctrl.integrators.modes.linear_modes`),
its eigenvalue of largest modulus ``lambda`` [1/s], and the position coordinate of ``z = (q, Y_0)``
with the largest entry of its eigenvector.
"""

from __future__ import annotations

import math

import numpy as np


def stiffest_mode(plant, x) -> tuple[str, float]:
    """``(coordinate, |lambda| [rad/s])`` of the eigenvalue of largest modulus of ``df/dx`` at ``x``;
    ``("unknown", nan)`` when the linearization cannot be formed (a non-finite state)."""
    from coopctrl.integrators.modes import linear_modes

    x = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(x)):
        return "unknown", math.nan
    try:
        modes = linear_modes(plant, x)
    except (ArithmeticError, ValueError, np.linalg.LinAlgError):
        return "unknown", math.nan
    k = int(np.argmax(np.abs(modes.eigenvalues)))
    v = np.abs(modes.eigenvectors[:plant.nz, k])
    names = plant.state_names()[:plant.nz]  # arm1_q3, object_x, ...
    return names[int(np.argmax(v))], float(abs(modes.eigenvalues[k]))
