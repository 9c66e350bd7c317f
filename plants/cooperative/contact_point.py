"""An actuated contact point: a contact node driven directly, without arm dynamics."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plants.errors import ParameterError


@dataclass(frozen=True)
class ContactPoint:
    """Replaces an arm by its contact node, actuated by a generalized force (the cheapest model).

    The node's pose is the coordinate (``Y_i = q_i``, ``J = I``, ``H = h = 0``), and the input
    is the generalized force on the node: ``(f [N], Q_A [N m])`` with ``Q_A = L^T tau_body`` in
    space, ``(f_x, f_z, n)`` in the plane.

    Attributes:
        space: ``"spatial"`` or ``"planar"``.
        name: Name used in messages.
        force_max: Optional bound on each input component, for the QP's limits [N, N m].
    """

    space: str = "spatial"
    name: str = "contact_point"
    force_max: float = float("inf")

    def __post_init__(self):
        if self.space not in ("spatial", "planar"):
            raise ParameterError(f"{self.name}.space", self.space, "'spatial' or 'planar'")
        if not (self.force_max > 0):
            raise ParameterError(f"{self.name}.force_max", self.force_max, "a number > 0")

    @property
    def dof(self) -> int:
        """Number of coordinates: 6 in space, 3 in the plane."""
        return 6 if self.space == "spatial" else 3

    @property
    def tau_max(self) -> np.ndarray:
        return np.full(self.dof, float(self.force_max))

    def pose(self, q) -> np.ndarray:
        return np.asarray(q, dtype=float).copy()

    def jacobian(self, q) -> np.ndarray:
        return np.eye(self.dof)

    def inverse_kinematics(self, Y_target, q0=None) -> np.ndarray:
        return np.asarray(Y_target, dtype=float).copy()
