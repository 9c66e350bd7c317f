"""A planar serial arm in the vertical x-z plane (docs/model.md s.2 planar scenes, s.4)."""

from __future__ import annotations

import itertools

from dataclasses import dataclass, field, replace

import numpy as np

from plants.arms._dls_ik import damped_least_squares
from plants._core import planar_arm_potential, planar_arm_terms
from plants.arms._validation import check_limits, check_vector, wrap_angle
from plants.arms.arm_queries import ArmQueries
from plants.arms.arm_terms import ArmTerms
from plants.arms.planar_link import PlanarLink
from plants.errors import ParameterError, UnreachablePoseError

#: IK convergence: position [m] and angle [rad] residuals.
IK_TOLERANCE = 1e-9


@dataclass(frozen=True, eq=False)
class PlanarArm(ArmQueries):
    """A planar serial arm: ``H(q) qdd + h(q, dq) = tau``, ``Y = Phi(q) = (x, z, theta)``.

    All joints turn about the normal of the x-z plane; ``theta`` [rad] is measured from +x
    towards +z and gravity acts along -z by default.

    Attributes:
        name: Name used in error messages.
        links: The links, base to tip.
        base: ``(x, z, theta)`` of joint 1's frame at ``q = 0`` [m, m, rad].
        tool: ``(dx, dz, dtheta)`` of the node frame in the last link frame, measured from
            the end of the last link [m, m, rad].
        gravity: ``(gx, gz)`` [m/s^2].
        tau_max: Joint torque limits [N m], (n,).
        q_limits: Joint limits ``[lower, upper]`` [rad], (n, 2).
    """

    name: str
    links: tuple
    base: np.ndarray = field(default_factory=lambda: np.zeros(3))
    tool: np.ndarray = field(default_factory=lambda: np.zeros(3))
    gravity: np.ndarray = field(default_factory=lambda: np.array([0.0, -9.81]))
    tau_max: np.ndarray = None
    q_limits: np.ndarray = None
    _table: np.ndarray = field(init=False, repr=False)

    space = "planar"

    def __post_init__(self):
        links = tuple(self.links)
        if not links or not all(isinstance(link, PlanarLink) for link in links):
            raise ParameterError("links", self.links, "a non-empty sequence of PlanarLink")
        n = len(links)
        object.__setattr__(self, "links", links)
        for name, length in (("base", 3), ("tool", 3), ("gravity", 2)):
            arr = check_vector(name, getattr(self, name), length)
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)
        q_limits = np.tile([-np.pi, np.pi], (n, 1)) if self.q_limits is None else self.q_limits
        tau_max = np.full(n, np.inf) if self.tau_max is None else self.tau_max
        tau, lim = check_limits("tau_max", tau_max, "q_limits", q_limits, n)
        object.__setattr__(self, "tau_max", tau)
        object.__setattr__(self, "q_limits", lim)
        table = np.ascontiguousarray(np.array([link.row() for link in links]))
        table.setflags(write=False)
        object.__setattr__(self, "_table", table)

    @property
    def dof(self) -> int:
        """Number of joints."""
        return len(self.links)

    def link_array(self) -> np.ndarray:
        """The packed (n, 7) float64 link table, a row per link as ``plants/core/planar_arm.h`` names it (read-only)."""
        return self._table

    dh_array = link_array

    def terms(self, q, dq) -> ArmTerms:
        """``H, h, Y, J, Jdq`` at ``(q [rad], dq [rad/s])`` in one kernel call."""
        n = self.dof
        q = self._joint_vector("q", q)
        dq = self._joint_vector("dq", dq)
        H = np.empty((n, n))
        h = np.empty(n)
        Y = np.empty(3)
        J = np.empty((3, n))
        Jdq = np.empty(3)
        planar_arm_terms(q, dq, self._table, self.base, self.tool, self.gravity, H, h, Y, J, Jdq)
        return ArmTerms(H, h, Y, J, Jdq)

    def potential(self, q) -> float:
        """Gravitational potential energy of the links [J]."""
        return float(planar_arm_potential(self._joint_vector("q", q), self._table, self.base, self.gravity))

    def with_base(self, base) -> "PlanarArm":
        """A copy of this arm with joint 1 at ``base = (x, z, theta)``."""
        return replace(self, base=base)

    def with_tool(self, tool) -> "PlanarArm":
        """A copy of this arm with the node frame ``tool = (dx, dz, dtheta)``."""
        return replace(self, tool=tool)

    def inverse_kinematics(self, Y_target, q0=None, seeds: int = 20, seed: int = 0) -> np.ndarray:
        """Joint angles [rad] within ``q_limits`` reaching ``Y_target = (x, z, theta)``.

        Damped least squares on (position error, wrapped angle error) from ``q0`` (default:
        the middle of the joint limits), then ``seeds`` random seeds drawn with ``seed``.

        Raises:
            UnreachablePoseError: No seed reached a residual of 1e-9 m and 1e-9 rad.
        """
        Y_target = check_vector("Y_target", Y_target, 3)
        lower, upper = self.q_limits[:, 0], self.q_limits[:, 1]

        def error_and_jacobian(q):
            t = self.terms(q, np.zeros(self.dof))
            e = Y_target - t.Y
            e[2] = wrap_angle(e[2])
            return e, t.J

        def converged(e):
            return np.linalg.norm(e[:2]) <= IK_TOLERANCE and abs(e[2]) <= IK_TOLERANCE

        rng = np.random.default_rng(seed)
        start0 = 0.5 * (lower + upper) if q0 is None else self._joint_vector("q0", q0)
        # the random seeds drawn only when the ones before did not converge (the same draws, in the same order)
        starts = itertools.chain([start0], (rng.uniform(lower, upper) for _ in range(seeds)))
        best_res = np.inf
        for start in starts:
            q, e = damped_least_squares(error_and_jacobian, start, lower, upper, converged)
            if converged(e):
                return q
            best_res = min(best_res, float(np.linalg.norm(e)))
        raise UnreachablePoseError(
            self.name,
            Y_target,
            best_res,
            "move the target or the arm base so that the pose is inside the workspace and joint limits",
        )

    def _joint_vector(self, where: str, value) -> np.ndarray:
        arr = np.ascontiguousarray(value, dtype=float).reshape(-1)
        if arr.shape != (self.dof,):
            raise ParameterError(where, value, f"{self.dof} joint values (got shape {np.shape(value)})")
        return arr
