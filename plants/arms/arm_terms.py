"""The result of one arm evaluation: everything (166)-(172) need (docs/model.md s.4)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ArmTerms:
    """Dynamics and kinematics of one arm at ``(q, dq)``.

    ``H qdd + h = tau``, ``Y = Phi(q)``, ``dY = J dq``, ``ddY = J qdd + Jdq``.

    Attributes:
        H: Joint-space inertia (n, n) [kg m^2].
        h: Coriolis, centrifugal, gravity and friction torques (n,) [N m].
        Y: Node pose, (6,) spatial (m, rad) or (3,) planar.
        J: Analytic Jacobian, (6, n) or (3, n).
        Jdq: ``dJ/dt dq``, (6,) or (3,).
    """

    H: np.ndarray
    h: np.ndarray
    Y: np.ndarray
    J: np.ndarray
    Jdq: np.ndarray
