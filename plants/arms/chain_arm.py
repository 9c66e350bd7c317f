"""A spatial serial arm with general joints (URDF-style): revolute, continuous, prismatic."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from plants._core import chain_arm_pose, chain_arm_potential, chain_arm_terms, chain_arm_terms_own_chart, chain_arm_tip
from plants.arms._validation import check_pose4, check_vector
from plants.arms.arm_queries import ArmQueries
from plants.arms.arm_terms import ArmTerms
from plants.arms.chain_joint import ChainJoint
from plants.arms.spatial_ik import SpatialInverseKinematics
from plants.errors import EulerSingularityError, ParameterError


@dataclass(frozen=True, eq=False)
class ChainArm(ArmQueries, SpatialInverseKinematics):
    """A spatial serial chain: ``H(q) qdd + h(q, dq) = tau``, ``Y = Phi(q)`` (166, 169).

    Link frame ``k`` is ``T_{k-1} origin_k M_k(q_k)`` (:class:`ChainJoint`). The node pose
    ``Y = (r, A)``: ``r`` [m] world position of the node frame (``tool`` in the last link
    frame), ``A`` its ZYX Euler angles [rad] (docs/model.md s.2). ``J`` is the analytic Jacobian
    into these coordinates (rows 3-5: ``dA/dt = L(A)^-1 R^T omega_world``). Gravity acts along
    ``gravity`` in the world, (0, 0, -9.81) by default: along -z of the base frame when
    ``base`` is not rotated.

    Attributes:
        name: Name used in error messages.
        joints: The moving joints, base to tip.
        base: World pose of the base frame, 4x4 [m].
        tool: Node frame in the last link frame, 4x4 [m].
        gravity: Gravity acceleration [m/s^2], (3,).
        tau_max: Joint effort limits [N m or N], (n,); ``inf`` = unlimited.
        q_limits: Joint limits ``[lower, upper]`` [rad or m], (n, 2); ``+-inf`` for a
            continuous joint.
        q_rest: Rest posture of the null-space posture task and of IK [rad or m], or ``None``
            (the middle of the joint limits, 0 for a continuous joint).
    """

    name: str
    joints: tuple
    base: np.ndarray = field(default_factory=lambda: np.eye(4))
    tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    tau_max: np.ndarray = None
    q_limits: np.ndarray = None
    q_rest: np.ndarray = None
    _table: np.ndarray = field(init=False, repr=False)

    space = "spatial"

    def __post_init__(self):
        joints = tuple(self.joints)
        if not joints or not all(isinstance(j, ChainJoint) for j in joints):
            raise ParameterError("joints", self.joints, "a non-empty sequence of ChainJoint")
        n = len(joints)
        object.__setattr__(self, "joints", joints)
        for name, value in (("base", self.base), ("tool", self.tool)):
            arr = check_pose4(name, value)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        gravity = check_vector("gravity", self.gravity, 3)
        gravity.setflags(write=False)
        object.__setattr__(self, "gravity", gravity)
        tau = np.full(n, np.inf) if self.tau_max is None else np.array(self.tau_max, dtype=float).reshape(-1)
        if tau.shape != (n,) or np.any(np.isnan(tau)) or np.any(tau <= 0.0):
            raise ParameterError("tau_max", self.tau_max, f"{n} effort limits > 0 [N m] (inf = unlimited)")
        lim = np.tile([-np.inf, np.inf], (n, 1)) if self.q_limits is None else np.array(self.q_limits, dtype=float)
        if lim.shape != (n, 2) or np.any(np.isnan(lim)) or np.any(lim[:, 0] >= lim[:, 1]):
            raise ParameterError("q_limits", self.q_limits, f"an ({n}, 2) array of [lower, upper] with lower < upper")
        tau.setflags(write=False)
        lim.setflags(write=False)
        object.__setattr__(self, "tau_max", tau)
        object.__setattr__(self, "q_limits", lim)
        if self.q_rest is not None:
            rest = check_vector("q_rest", self.q_rest, n)
            if np.any(rest < lim[:, 0]) or np.any(rest > lim[:, 1]):
                raise ParameterError("q_rest", self.q_rest, "a posture within q_limits")
            rest.setflags(write=False)
            object.__setattr__(self, "q_rest", rest)
        table = np.ascontiguousarray(np.array([j.row() for j in joints]))
        table.setflags(write=False)
        object.__setattr__(self, "_table", table)

    @property
    def dof(self) -> int:
        """Number of moving joints."""
        return len(self.joints)

    @property
    def joint_names(self) -> tuple:
        """Names of the moving joints, base to tip."""
        return tuple(j.name for j in self.joints)

    def kernel_table(self) -> np.ndarray:
        """The packed (n, 32) joint table, a row per joint as ``plants/core/chain_arm.h`` names it
        (``ChainJointRow``, :meth:`ChainJoint.row`; read-only)."""
        return self._table

    def kernel_tool(self) -> np.ndarray:
        """The node frame in the last link frame, 4x4 [m]."""
        return self.tool

    def rest_posture(self) -> np.ndarray:
        """Rest posture [rad or m]: ``q_rest``, else the middle of the joint limits."""
        return SpatialInverseKinematics.rest_posture(self) if self.q_rest is None else self.q_rest.copy()

    # ---- evaluation ----------------------------------------------------------------------
    def terms(self, q, dq) -> ArmTerms:
        """``H, h, Y, J, Jdq`` at ``(q, dq)`` in one call of the compiled core (``chain_arm_terms``)."""
        n = self.dof
        q = self._joint_vector("q", q)
        dq = self._joint_vector("dq", dq)
        H = np.empty((n, n))
        h = np.empty(n)
        Y = np.empty(6)
        J = np.empty((6, n))
        Jdq = np.empty(6)
        status = chain_arm_terms(q, dq, self._table, self.base, self.tool, self.gravity, H, h, Y, J, Jdq)
        if status == 1:
            theta = float(Y[4])
            raise EulerSingularityError(f"arm '{self.name}' tip", theta, float(np.cos(theta)))
        return ArmTerms(H, h, Y, J, Jdq)

    def terms_in_own_chart(self, q, dq) -> tuple:
        """``(terms, C)``: :meth:`terms` with the node's angles taken in its own chart ``C = R_tip(q)`` (3x3;
        ``Y[3:6] = 0``, docs/model.md s.2, rotation charts), as a cooperative plant with ``arm_charts="own"``
        takes them. Defined at every pose (no Euler singularity); ``H``, ``h`` and the translational rows are
        :meth:`terms`'s. One call of the compiled core (``chain_arm_terms_own_chart``)."""
        n = self.dof
        q = self._joint_vector("q", q)
        dq = self._joint_vector("dq", dq)
        H, h, Y, J, Jdq, C = np.empty((n, n)), np.empty(n), np.empty(6), np.empty((6, n)), np.empty(6), np.empty((3, 3))
        chain_arm_terms_own_chart(q, dq, self._table, self.base, self.tool, self.gravity, H, h, Y, J, Jdq, C)
        return ArmTerms(H, h, Y, J, Jdq), C

    def pose(self, q) -> np.ndarray:
        """Node pose ``Y = Phi(q)`` [m, rad] (169): ``terms(q, 0).Y`` bit for bit, by forward kinematics alone."""
        Y = np.empty(6)
        if chain_arm_pose(self._joint_vector("q", q), self._table, self.base, self.tool, False, Y) == 1:
            theta = float(Y[4])
            raise EulerSingularityError(f"arm '{self.name}' tip", theta, float(np.cos(theta)))
        return Y

    def potential(self, q) -> float:
        """Gravitational potential energy of the links [J] (``-sum m g . p_com``)."""
        return float(chain_arm_potential(self._joint_vector("q", q), self._table, self.base, self.gravity))

    def tip_transform(self, q) -> tuple:
        """``(T, Jg)``: node-frame world pose 4x4 and geometric Jacobian (v; omega_world)."""
        T = np.empty((4, 4))
        Jg = np.empty((6, self.dof))
        chain_arm_tip(self._joint_vector("q", q), self._table, self.base, self.tool, T, Jg)
        return T, Jg

    # ---- variants ------------------------------------------------------------------------
    def with_base(self, base) -> "ChainArm":
        """A copy of this arm mounted at ``base`` (4x4 world pose [m])."""
        return replace(self, base=base)

    def with_tool(self, tool) -> "ChainArm":
        """A copy of this arm with the node frame ``tool`` (4x4, in the last link frame)."""
        return replace(self, tool=tool)

    def _joint_vector(self, where: str, value) -> np.ndarray:
        arr = np.ascontiguousarray(value, dtype=float).reshape(-1)
        if arr.shape != (self.dof,):
            raise ParameterError(where, value, f"{self.dof} joint values (got shape {np.shape(value)})")
        return arr
