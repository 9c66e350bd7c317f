"""The stiffest mode of the plant at a state, named by the coordinate that moves most in it.

Used to explain why an error-controlled integrator's step collapsed (:class:`~coopctrl.errors.StepTooSmall`):
the linearization ``A = df/dx`` at the failing state (:func:`coopctrl.integrators.modes.linear_modes`),
its eigenvalue of largest modulus ``lambda`` [1/s], and the position coordinate of ``z = (q, Y_0)``
with the largest entry of its eigenvector.
"""

from __future__ import annotations

import math

import numpy as np


def state_coordinates(plant) -> list[str]:
    """Names of the position coordinates ``z = (q, Y_0)``: ``"<arm> joint <j>"``, then the object's pose."""
    from coopctrl.tuning import signal_names

    names = []
    for i, arm in enumerate(plant.arms):
        names += [f"{arm.name} joint {j + 1}" for j in range(arm.dof)]
    return names + list(signal_names.object_pose(plant.space))


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
    names = state_coordinates(plant)
    return names[int(np.argmax(v))] if len(names) == plant.nz else f"coordinate {int(np.argmax(v))}", \
        float(abs(modes.eigenvalues[k]))
