"""The single-quantity queries every arm answers, all from its one-pass ``terms(q, dq)``."""

from __future__ import annotations

import numpy as np


class ArmQueries:
    """Mixin: ``inertia``, ``bias``, ``pose``, ``jacobian``, ``jacobian_dot_qd`` and ``kinetic``
    read from ``self.terms(q, dq)`` (``H q'' + h = tau``, ``Y = Phi(q)``, ``J``, ``dJ/dt dq``;
    docs/model.md s.4, 166-172). A class using it provides ``dof``, ``terms`` and ``_joint_vector``."""

    def inertia(self, q) -> np.ndarray:
        """Joint-space inertia ``H(q)`` [kg m^2]."""
        return self.terms(q, np.zeros(self.dof)).H

    def bias(self, q, dq) -> np.ndarray:
        """``h(q, dq)``: Coriolis, centrifugal, gravity and viscous torques [N m]."""
        return self.terms(q, dq).h

    def pose(self, q) -> np.ndarray:
        """Node pose ``Y = Phi(q)`` [m, rad] (169)."""
        return self.terms(q, np.zeros(self.dof)).Y

    def jacobian(self, q) -> np.ndarray:
        """Analytic Jacobian ``J = dY/dq`` (p, n) (170)."""
        return self.terms(q, np.zeros(self.dof)).J

    def jacobian_dot_qd(self, q, dq) -> np.ndarray:
        """``dJ/dt dq`` (171): the node acceleration in ``Y`` coordinates when ``qdd = 0``."""
        return self.terms(q, dq).Jdq

    def kinetic(self, q, dq) -> float:
        """Kinetic energy ``1/2 dq^T H dq`` [J] (motor inertias included when on)."""
        dq = self._joint_vector("dq", dq)
        return 0.5 * float(dq @ self.inertia(q) @ dq)
