"""One moving joint of a general serial chain and the rigid link it carries (docs/model.md s.4)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plants.arms.chain_table import (
    CHAIN_COLUMNS,
    COL_AXIS,
    COL_I,
    COL_MASS,
    COL_MOTOR,
    COL_ORIGIN,
    COL_RC,
    COL_ROT,
    COL_TYPE,
    COL_VISCOUS,
    COL_COULOMB,
    JOINT_PRISMATIC,
    JOINT_REVOLUTE,
    JOINT_REVOLUTE_Z,
)
from plants.arms._validation import check_finite, check_inertia, check_nonnegative, check_pose4
from plants.errors import ParameterError

JOINT_KINDS = ("revolute", "prismatic")


@dataclass(frozen=True, eq=False)
class ChainJoint:
    """A revolute or prismatic joint at a fixed ``origin`` in its parent link frame.

    Link frame ``k`` is ``T_{k-1} origin Rot(axis, q)`` (revolute, ``q`` [rad]) or
    ``T_{k-1} origin Trans(axis q)`` (prismatic, ``q`` [m]). The link's mass properties are in
    link frame ``k`` (after the motion).

    Attributes:
        name: Joint name, used in error messages.
        kind: ``"revolute"`` or ``"prismatic"``.
        origin: Joint frame in the parent link frame, 4x4 [m].
        axis: Unit joint axis in the joint frame, 3 numbers.
        mass: Link mass [kg], >= 0.
        com: Centre of mass in the link frame [m], 3 numbers.
        inertia: Inertia about the COM in the link frame, 3x3 [kg m^2], symmetric PSD.
        motor_inertia: Reflected rotor inertia added to ``H[k, k]`` [kg m^2 or kg], >= 0.
        viscous: Viscous joint friction [N m s/rad or N s/m], >= 0.
        coulomb: Coulomb joint friction [N m or N], >= 0, smoothed as
            ``coulomb tanh(dq / COULOMB_SMOOTHING)``.
    """

    name: str
    kind: str
    origin: np.ndarray
    axis: tuple = (0.0, 0.0, 1.0)
    mass: float = 0.0
    com: tuple = (0.0, 0.0, 0.0)
    inertia: np.ndarray = None
    motor_inertia: float = 0.0
    viscous: float = 0.0
    coulomb: float = 0.0

    def __post_init__(self):
        where = f"joint '{self.name}'"
        if self.kind not in JOINT_KINDS:
            raise ParameterError(f"{where}.type", self.kind, f"one of {list(JOINT_KINDS)} (fixed joints are folded in)")
        origin = check_pose4(f"{where}.origin", self.origin)
        origin.setflags(write=False)  # immutable, as the joint: a serial arm's joints are shared (SerialArm.chain_joints)
        object.__setattr__(self, "origin", origin)
        axis = np.array(self.axis, dtype=float).reshape(-1)
        if axis.shape != (3,) or not np.all(np.isfinite(axis)) or np.linalg.norm(axis) < 1e-12:
            raise ParameterError(f"{where}.axis", self.axis, "a non-zero 3-vector")
        object.__setattr__(self, "axis", tuple(float(v) for v in axis / np.linalg.norm(axis)))
        for name in ("mass", "motor_inertia", "viscous", "coulomb"):
            value = float(getattr(self, name))
            check_nonnegative(f"{where}.{name}", value)
            object.__setattr__(self, name, value)
        com = np.array(self.com, dtype=float).reshape(-1)
        if com.shape != (3,):
            raise ParameterError(f"{where}.com", self.com, "3 numbers [m]")
        check_finite(f"{where}.com", com)
        object.__setattr__(self, "com", tuple(float(v) for v in com))
        inertia = np.zeros((3, 3)) if self.inertia is None else np.array(self.inertia, dtype=float)
        if inertia.shape != (3, 3):
            raise ParameterError(f"{where}.inertia", self.inertia, "a 3x3 inertia matrix [kg m^2]")
        # Symmetrize rounding in parsed data; PSD is required, the triangle inequality is not
        # (published URDF inertias of real arms violate it slightly).
        inertia = 0.5 * (inertia + inertia.T)
        check_inertia(f"{where}.inertia", inertia, self.mass, triangle=False)
        inertia.setflags(write=False)
        object.__setattr__(self, "inertia", inertia)

    def row(self) -> np.ndarray:
        """The packed kernel row (32,) as ``plants/core/chain_arm.h``'s ``ChainJointRow`` names it: ``[type,
        origin(3), rotation(9), axis(3), mass, com(3), inertia(6), motor_inertia, viscous, coulomb, 0, 0, 0]``."""
        r = np.zeros(CHAIN_COLUMNS)
        axis = np.array(self.axis)
        if self.kind == "prismatic":
            r[COL_TYPE] = JOINT_PRISMATIC
        elif np.array_equal(axis, [0.0, 0.0, 1.0]):
            r[COL_TYPE] = JOINT_REVOLUTE_Z
        else:
            r[COL_TYPE] = JOINT_REVOLUTE
        r[COL_ORIGIN:COL_ORIGIN + 3] = self.origin[:3, 3]
        r[COL_ROT:COL_ROT + 9] = self.origin[:3, :3].reshape(-1)
        r[COL_AXIS:COL_AXIS + 3] = axis
        r[COL_MASS] = self.mass
        r[COL_RC:COL_RC + 3] = self.com
        I = self.inertia
        r[COL_I:COL_I + 6] = (I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[0, 2])
        r[COL_MOTOR] = self.motor_inertia
        r[COL_VISCOUS] = self.viscous
        r[COL_COULOMB] = self.coulomb
        return r
