"""One link of a spatial serial arm, standard Denavit-Hartenberg (docs/model.md s.4)."""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from plants.arms._validation import check_inertia, check_magnitude, check_nonnegative
from plants.errors import ParameterError


@dataclass(frozen=True)
class DHLink:
    """A revolute joint and the link it moves, in standard DH as Corke's Robotics Toolbox.

    Frame k follows frame k-1 by ``Rz(q + offset) Tz(d) Tx(a) Rx(alpha)``; the joint turns
    about ``z_{k-1}``. The mass properties are in frame k (as ``rtb.RevoluteDH(r=..., I=...)``).

    Every number is finite, of magnitude at most :data:`plants.arms._validation.MAX_MAGNITUDE`
    (SI units).

    Attributes:
        a: Link length [m].
        alpha: Link twist [rad].
        d: Link offset along ``z_{k-1}`` [m].
        offset: Joint angle offset [rad].
        mass: Link mass [kg], >= 0.
        rc: Centre of mass in the link frame [m], 3 numbers.
        inertia: Inertia about the COM in the link frame [kg m^2], as
            ``(Ixx, Iyy, Izz, Ixy, Iyz, Ixz)``; symmetric PSD, and for ``mass > 0`` principal
            moments satisfying the triangle inequality (a massless link may carry a lumped
            inertia, as the Puma 560's link 1).
        motor_inertia: Reflected motor inertia ``Jm G^2`` [kg m^2] added to ``H[k, k]``
            (0 = off, the default).
        viscous: Joint viscous friction ``B G^2`` [N m s/rad] (0 = off, the default).
        check_triangle_inequality: Require the triangle inequality of the principal moments
            (default). Turn off only for published identified data that violate it (the
            Puma 560's link 3); positive semi-definiteness is always required.
    """

    a: float = 0.0
    alpha: float = 0.0
    d: float = 0.0
    offset: float = 0.0
    mass: float = 0.0
    rc: tuple = (0.0, 0.0, 0.0)
    inertia: tuple = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    motor_inertia: float = 0.0
    viscous: float = 0.0
    check_triangle_inequality: bool = True

    def __post_init__(self):
        where = "DHLink"
        for name in ("a", "alpha", "d", "offset", "mass", "motor_inertia", "viscous"):
            value = getattr(self, name)
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"{where}.{name}", value, "a number") from None
            check_magnitude(f"{where}.{name}", value)
            object.__setattr__(self, name, value)
        check_nonnegative(f"{where}.mass", self.mass)
        check_nonnegative(f"{where}.motor_inertia", self.motor_inertia)
        check_nonnegative(f"{where}.viscous", self.viscous)
        rc = np.array(self.rc, dtype=float).reshape(-1)
        if rc.shape != (3,):
            raise ParameterError(f"{where}.rc", self.rc, "3 numbers [m]")
        check_magnitude(f"{where}.rc", rc)
        object.__setattr__(self, "rc", tuple(float(v) for v in rc))
        inertia = np.array(self.inertia, dtype=float)
        if inertia.shape == (3, 3):
            if np.max(np.abs(inertia - inertia.T), initial=0.0) > 1e-12 * max(np.max(np.abs(inertia)), 1e-300):
                raise ParameterError(f"{where}.inertia", self.inertia, "a symmetric 3x3 inertia matrix")
            inertia = np.array([inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[0, 1], inertia[1, 2], inertia[0, 2]])
        if inertia.shape != (6,):
            raise ParameterError(f"{where}.inertia", self.inertia, "(Ixx, Iyy, Izz, Ixy, Iyz, Ixz) or a 3x3 matrix")
        check_magnitude(f"{where}.inertia", inertia)
        object.__setattr__(self, "inertia", tuple(float(v) for v in inertia))
        check_inertia(f"{where}.inertia", self.inertia_matrix(), self.mass, self.check_triangle_inequality)

    def inertia_matrix(self) -> np.ndarray:
        """The 3x3 inertia about the COM in the link frame [kg m^2]."""
        ixx, iyy, izz, ixy, iyz, ixz = self.inertia
        return np.array([[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]])

    def row(self) -> np.ndarray:
        """The packed kernel row (16,) as ``plants/core/dh_arm.h``'s ``DHLink`` names it:
        ``[a, alpha, d, offset, mass, com(3) = rc, inertia(6), motor_inertia, viscous]``."""
        return np.array(
            [self.a, self.alpha, self.d, self.offset, self.mass, *self.rc, *self.inertia, self.motor_inertia, self.viscous]
        )

    @classmethod
    def named(cls, where: str, **kwargs) -> "DHLink":
        """Build a link, naming errors ``{where}.{field}`` (e.g. ``links[2].mass``)."""
        unknown = set(kwargs) - {f.name for f in fields(cls)}
        if unknown:
            raise ParameterError(where, sorted(unknown), f"fields of DHLink {[f.name for f in fields(cls)]}")
        try:
            return cls(**kwargs)
        except ParameterError as err:
            raise ParameterError(err.parameter.replace("DHLink", where, 1), err.value, err.allowed) from None
