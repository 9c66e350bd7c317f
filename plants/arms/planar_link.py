"""One link of a planar serial arm in the vertical x-z plane (docs/model.md s.2 and s.4)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from plants.arms._validation import check_finite, check_nonnegative
from plants.errors import ParameterError


@dataclass(frozen=True)
class PlanarLink:
    """A revolute joint (axis normal to the x-z plane) and the link it moves.

    Attributes:
        length: Distance from this joint to the next [m], >= 0.
        mass: Link mass [kg], >= 0.
        rc: Centre of mass in the link frame [m]: along the link and perpendicular to it
            towards +theta.
        izz: Inertia about the COM, about the plane normal [kg m^2], >= 0.
        motor_inertia: Reflected motor inertia [kg m^2] added to ``H[k, k]`` (0 = off).
        viscous: Joint viscous friction [N m s/rad] (0 = off).
    """

    length: float
    mass: float = 0.0
    rc: tuple = (0.0, 0.0)
    izz: float = 0.0
    motor_inertia: float = 0.0
    viscous: float = 0.0

    def __post_init__(self):
        where = "PlanarLink"
        for name in ("length", "mass", "izz", "motor_inertia", "viscous"):
            value = getattr(self, name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"{where}.{name}", value, "a number") from None
            check_nonnegative(f"{where}.{name}", value)
            object.__setattr__(self, name, value)
        rc = np.array(self.rc, dtype=float).reshape(-1)
        if rc.shape != (2,):
            raise ParameterError(f"{where}.rc", self.rc, "2 numbers [m]")
        check_finite(f"{where}.rc", rc)
        object.__setattr__(self, "rc", tuple(float(v) for v in rc))

    def row(self) -> np.ndarray:
        """The packed kernel row ``[length, mass, rc_x, rc_y, Izz, motor_inertia, viscous]``."""
        return np.array([self.length, self.mass, *self.rc, self.izz, self.motor_inertia, self.viscous])

    @classmethod
    def named(cls, where: str, **kwargs) -> "PlanarLink":
        """Build a link, naming errors ``{where}.{field}`` (e.g. ``links[2].mass``)."""
        unknown = set(kwargs) - {f.name for f in fields(cls)}
        if unknown:
            raise ParameterError(where, sorted(unknown), f"fields of PlanarLink {[f.name for f in fields(cls)]}")
        try:
            return cls(**kwargs)
        except ParameterError as err:
            raise ParameterError(err.parameter.replace("PlanarLink", where, 1), err.value, err.allowed) from None
