"""A node of the elastic system: a lumped rigid body (docs/model.md s.1, 104-105)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plants import _validation as v
from plants.errors import ParameterError


@dataclass(frozen=True)
class Node:
    """Lumped body at a node: the object's mass centre (node 0) or a contact interconnection.

    Attributes:
        mass: Mass in [kg], > 0.
        inertia: Principal moments of inertia about the node's mass centre in [kg m^2]:
            3 values ``(I1, I2, I3)`` in space (they must satisfy the triangle inequality of a
            physical rigid body, so the tensor is positive definite), 1 value in the plane.
        name: Label used in error messages (``"nodes[2]"``).
    """

    mass: float
    inertia: tuple[float, ...]
    name: str = "node"

    def __post_init__(self):
        object.__setattr__(self, "mass", v.positive(f"{self.name}.mass", self.mass))
        I = np.atleast_1d(v.finite_array(f"{self.name}.inertia", self.inertia))
        if I.shape not in ((1,), (3,)):
            raise ParameterError(f"{self.name}.inertia", self.inertia, "3 principal moments (spatial) or 1 (planar)")
        if np.any(I <= 0.0):
            raise ParameterError(f"{self.name}.inertia", self.inertia, "a positive-definite inertia: every moment > 0")
        if I.shape == (3,):
            a, b, c = I
            if a + b < c or b + c < a or a + c < b:
                raise ParameterError(
                    f"{self.name}.inertia", self.inertia,
                    "principal moments satisfying the triangle inequality (I1 + I2 >= I3, ...) of a rigid body",
                )
        object.__setattr__(self, "inertia", tuple(float(x) for x in I))

    @property
    def space(self) -> str:
        return "spatial" if len(self.inertia) == 3 else "planar"
