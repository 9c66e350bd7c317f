"""A spatial serial arm with revolute standard-DH joints (docs/model.md s.4, (166)-(172))."""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, replace

import numpy as np

from plants._core import dh_arm_potential, dh_arm_terms, dh_arm_tip
from plants.arms._validation import check_limits, check_pose4, check_vector
from plants.arms.arm_queries import ArmQueries
from plants.arms.arm_terms import ArmTerms
from plants.arms.chain_joint import ChainJoint
from plants.arms.dh_link import DHLink
from plants.arms.spatial_ik import IK_TOLERANCE, SpatialInverseKinematics  # noqa: F401 (re-export)
from plants.errors import EulerSingularityError, ParameterError


@dataclass(frozen=True, eq=False)
class SerialArm(ArmQueries, SpatialInverseKinematics):
    """A spatial serial arm: ``H(q) qdd + h(q, dq) = tau``, ``Y = Phi(q)`` (166, 169).

    The node pose ``Y = (r, A)``: ``r`` [m] world position of the tool frame origin, ``A``
    its ZYX Euler angles [rad] (docs/model.md s.2). ``J`` is the analytic Jacobian into these
    coordinates (rows 3-5: ``dA/dt = L(A)^-1 R^T omega_world``).

    Attributes:
        name: Name used in error messages.
        links: The DH links, base to tip.
        base: World pose of the base frame (frame 0), 4x4 [m].
        tool: Node frame in the last DH frame, 4x4 [m].
        gravity: Gravity acceleration [m/s^2], (3,).
        tau_max: Joint torque limits [N m], (n,).
        q_limits: Joint limits ``[lower, upper]`` [rad], (n, 2).
    """

    name: str
    links: tuple
    base: np.ndarray = field(default_factory=lambda: np.eye(4))
    tool: np.ndarray = field(default_factory=lambda: np.eye(4))
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, 0.0, -9.81]))
    tau_max: np.ndarray = None
    q_limits: np.ndarray = None
    _dh: np.ndarray = field(init=False, repr=False)

    space = "spatial"

    def __post_init__(self):
        links = tuple(self.links)
        if not links or not all(isinstance(link, DHLink) for link in links):
            raise ParameterError("links", self.links, "a non-empty sequence of DHLink")
        n = len(links)
        object.__setattr__(self, "links", links)
        for name, value in (("base", self.base), ("tool", self.tool)):
            arr = check_pose4(name, value)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        gravity = check_vector("gravity", self.gravity, 3)
        gravity.setflags(write=False)
        object.__setattr__(self, "gravity", gravity)
        # No torque limits given: unlimited (inf); no joint limits given: [-pi, pi].
        q_limits = np.tile([-np.pi, np.pi], (n, 1)) if self.q_limits is None else self.q_limits
        tau_max = np.full(n, np.inf) if self.tau_max is None else self.tau_max
        tau, lim = check_limits("tau_max", tau_max, "q_limits", q_limits, n)
        object.__setattr__(self, "tau_max", tau)
        object.__setattr__(self, "q_limits", lim)
        dh = np.ascontiguousarray(np.array([link.row() for link in links]))
        dh.setflags(write=False)
        object.__setattr__(self, "_dh", dh)

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.links)

    def dh_array(self) -> np.ndarray:
        """The packed (n, 16) float64 DH table, a row per link as ``plants/core/dh_arm.h`` names it (``DHLink``:
        a, alpha, d, offset, mass, com(3), inertia(6), motor_inertia, viscous; read-only)."""
        return self._dh

    def chain_joints(self) -> tuple:
        """The same arm as general-chain joints (:class:`ChainJoint`), exactly.

        With ``G_k = Tz(d_k) Tx(a_k) Rx(alpha_k)``, DH frame ``k`` is ``L_k G_k`` where link frame
        ``L_k = L_{k-1} G_{k-1} Rz(offset_k) Rz(q_k)``: joint ``k``'s origin is
        ``G_{k-1} Rz(offset_k)`` (``G_0 = I``), its axis +z, and link ``k``'s mass properties are
        carried from DH frame ``k`` to ``L_k`` by ``G_k``. The node frame in ``L_n`` is
        :meth:`kernel_tool`. Built once per arm name and DH table (both immutable) and shared.
        """
        return _chain_joints(self.name, self.links)

    def kernel_table(self) -> np.ndarray:
        """The (n, 32) joint table of :mod:`plants.arms.chain_table` for this arm (a new array: the
        table is computed once per arm name and DH table, and copied)."""
        return _kernel_table(self.name, self.links).copy()

    def kernel_tool(self) -> np.ndarray:
        """The node frame in the last link frame of :meth:`chain_joints`, 4x4 [m]."""
        return _dh_fixed(self.links[-1]) @ self.tool

    # ---- evaluation ----------------------------------------------------------------------
    def terms(self, q, dq) -> ArmTerms:
        """``H, h, Y, J, Jdq`` at ``(q [rad], dq [rad/s])`` in one call of the compiled core (``dh_arm_terms``)."""
        n = self.dof
        q = self._joint_vector("q", q)
        dq = self._joint_vector("dq", dq)
        H = np.empty((n, n))
        h = np.empty(n)
        Y = np.empty(6)
        J = np.empty((6, n))
        Jdq = np.empty(6)
        status = dh_arm_terms(q, dq, self._dh, self.base, self.tool, self.gravity, H, h, Y, J, Jdq)
        if status == 1:
            theta = float(Y[4])
            raise EulerSingularityError(f"arm '{self.name}' tip", theta, float(np.cos(theta)))
        return ArmTerms(H, h, Y, J, Jdq)

    def potential(self, q) -> float:
        """Gravitational potential energy of the links [J] (``-sum m g . p_com``)."""
        return float(dh_arm_potential(self._joint_vector("q", q), self._dh, self.base, self.gravity))

    def tip_transform(self, q) -> tuple:
        """``(T, Jg)``: tool-frame world pose 4x4 and geometric Jacobian (v; omega_world).

        Defined everywhere, also where the Euler angles of the tip are singular.
        """
        T = np.empty((4, 4))
        Jg = np.empty((6, self.dof))
        dh_arm_tip(self._joint_vector("q", q), self._dh, self.base, self.tool, T, Jg)
        return T, Jg

    # ---- variants ------------------------------------------------------------------------
    def with_base(self, base) -> "SerialArm":
        """A copy of this arm mounted at ``base`` (4x4 world pose [m])."""
        return replace(self, base=base)

    def with_tool(self, tool) -> "SerialArm":
        """A copy of this arm with the node frame ``tool`` (4x4, in the last DH frame)."""
        return replace(self, tool=tool)

    # ---- helpers -------------------------------------------------------------------------
    def _joint_vector(self, where: str, value) -> np.ndarray:
        arr = np.ascontiguousarray(value, dtype=float).reshape(-1)
        if arr.shape != (self.dof,):
            raise ParameterError(where, value, f"{self.dof} joint values (got shape {np.shape(value)})")
        return arr


@functools.lru_cache(maxsize=64)
def _chain_joints(name: str, links: tuple) -> tuple:
    """:meth:`SerialArm.chain_joints` of an arm named ``name`` with the DH ``links`` (frozen, hashable)."""
    joints = []
    G_prev = np.eye(4)
    for k, link in enumerate(links):
        Rz = np.eye(4)
        c, s = np.cos(link.offset), np.sin(link.offset)
        Rz[:2, :2] = [[c, -s], [s, c]]
        G = _dh_fixed(link)
        RG = G[:3, :3]
        joints.append(ChainJoint(
            name=f"{name}.links[{k}]", kind="revolute", origin=G_prev @ Rz, axis=(0.0, 0.0, 1.0),
            mass=link.mass, com=G[:3, :3] @ np.array(link.rc) + G[:3, 3], inertia=RG @ link.inertia_matrix() @ RG.T,
            motor_inertia=link.motor_inertia, viscous=link.viscous))
        G_prev = G
    return tuple(joints)


@functools.lru_cache(maxsize=64)
def _kernel_table(name: str, links: tuple) -> np.ndarray:
    """The (n, 32) joint table of :func:`_chain_joints` (read-only: callers get a copy)."""
    table = np.ascontiguousarray(np.array([j.row() for j in _chain_joints(name, links)]))
    table.setflags(write=False)
    return table


def _dh_fixed(link) -> np.ndarray:
    """``Tz(d) Tx(a) Rx(alpha)`` of a DH link, 4x4."""
    c, s = np.cos(link.alpha), np.sin(link.alpha)
    return np.array([[1.0, 0.0, 0.0, link.a], [0.0, c, -s, 0.0], [0.0, s, c, link.d], [0.0, 0.0, 0.0, 1.0]])
