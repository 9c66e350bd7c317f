"""The closed loop in rotation charts (``scene.rotations = "charts"``; docs/model.md s.2, rotation charts).

A charted plant (:attr:`plants.cooperative.CooperativePlant.charted`) takes each arm's node in its own
chart and the object and contact points in stored charts ``C_k``: ``R_k = C_k R(A_k)``. The kernel runs
unchanged on the chart coordinates; between kernel calls (every :data:`CHART_CHUNK` ticks) the loop
re-centres the stored charts when the smallest ``|cos theta|`` of their angles falls below
:data:`RECENTRE_COS` (:class:`LoopCharts`): ``C' = C R(A)``, ``A' = 0``, the same body angular
velocity (:meth:`~plants.cooperative.CooperativePlant.recentred`), the kernel's packed node rows and the
state updated in place. After the run the record is turned back into the book's world coordinates where
they exist (:meth:`LoopCharts.book_record`), with the object's rotation kept exactly as a quaternion.

Why ``RECENTRE_COS = 0.7`` (45.6 deg from the chart's centre): there ``1/cos(theta)``, the growth of
``L^-1`` and of the fastest rotational mode (docs/model.md s.2), is at most 1.43, so a chart never costs
more than that factor in conditioning, while a re-centring (a few 3x3 products, exact up to rounding)
is needed only once per 45 deg of turn. A chunk of :data:`CHART_CHUNK` ticks leaves 44 deg to the
chart's singularity: the object may turn at up to 0.77 / (``CHART_CHUNK`` T) rad/s (38 rad/s at
T = 1 ms) between two checks; a faster turn meets the plant's own singularity status
(:class:`~plants.errors.EulerSingularityError`, a stop with its cause), never a wrong number.

The nominal trajectory table: in this release the controllers do not run in charts (the scenario
refuses ``scene.rotations = "charts"`` with ``controllers.enabled = true``), so in a charted run the
table only feeds the nominal node motion's bookkeeping; each row is expressed in the chart centred on
its own target (:func:`own_chart_table`: ``A = 0``, defined at every rotation), and the record's
``Y0_nominal`` is the target in the book's world angles (:meth:`LoopCharts.book_record`).
"""

from __future__ import annotations

import numpy as np

import coopctrl.trajectory.quaternion as quat
from plants.frames import EULER_SINGULARITY_COS

#: Re-centre the stored charts below this smallest ``|cos theta|`` [-] (module docstring: why 0.7).
RECENTRE_COS = 0.7
#: Ticks per kernel call of a charted run (how often the charts are checked; module docstring).
CHART_CHUNK = 20


def euler_of(R) -> np.ndarray:
    """ZYX angles (N, 3) [rad] of rotations ``R`` (N, 3, 3), ``theta`` in [-pi/2, pi/2]
    (:func:`plants.frames.euler_zyx_from_rotation`, stacked)."""
    return np.stack([np.arctan2(R[:, 1, 0], R[:, 0, 0]),
                     np.arctan2(-R[:, 2, 0], np.hypot(R[:, 2, 1], R[:, 2, 2])),
                     np.arctan2(R[:, 2, 1], R[:, 2, 2])], axis=1)


def rotations_of(A) -> np.ndarray:
    """``R(A) = Rz(psi) Ry(theta) Rx(phi)`` (N, 3, 3) of ZYX angles ``A`` (N, 3) [rad]."""
    return quat.matrix(quat.from_zyx(A))


def body_rates(A, dA) -> np.ndarray:
    """``omega = L(A) dA`` (N, 3) [rad/s] (docs/model.md s.2, (105)), stacked."""
    cth, sth = np.cos(A[:, 1]), np.sin(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    return np.stack([-sth * dA[:, 0] + dA[:, 2],
                     sph * cth * dA[:, 0] + cph * dA[:, 1],
                     cph * cth * dA[:, 0] - sph * dA[:, 1]], axis=1)


def euler_rates(A, w) -> np.ndarray:
    """``L(A)^-1 w`` (N, 3) for body vectors ``w`` (N, 3). Where the angles have no rates
    (``|cos theta| < EULER_SINGULARITY_COS``) ``cos theta`` is held at that bound, with its sign: the
    rates there are those at pitch +-(90 deg - 1e-6 rad), finite (the book's coordinates do not exist at
    pitch +-90 deg; the record keeps the exact rotation in ``object_rotation``)."""
    cth = np.cos(A[:, 1])
    cth = np.where(np.abs(cth) < EULER_SINGULARITY_COS, np.where(cth < 0.0, -1.0, 1.0) * EULER_SINGULARITY_COS, cth)
    sth = np.sin(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    yz = sph * w[:, 1] + cph * w[:, 2]
    return np.stack([yz / cth, cph * w[:, 1] - sph * w[:, 2], w[:, 0] + yz * sth / cth], axis=1)


def rate_map_dot_times(A, dA) -> np.ndarray:
    """``dL(A, dA) dA`` (N, 3) (:func:`plants.frames.body_rate_map_dot` times ``dA``), stacked."""
    cth, sth = np.cos(A[:, 1]), np.sin(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    dps, dth, dph = dA[:, 0], dA[:, 1], dA[:, 2]
    return np.stack([-cth * dth * dps,
                     (cph * cth * dph - sph * sth * dth) * dps - sph * dph * dth,
                     (-sph * cth * dph - cph * sth * dth) * dps - cph * dph * dth], axis=1)


def target_motion(trajectory, times):
    """The nominal object motion at ``times`` (N,) [s] on the rotation group: ``(r, dr, ddr, R, omega_b,
    alpha_b)``, positions [m, m/s, m/s^2] (N, 3), rotations (N, 3, 3), body angular velocity [rad/s] and
    acceleration [rad/s^2] (N, 3). A :class:`~coopctrl.trajectory.GeodesicTrajectory` gives it at every
    rotation (``sample_rotation``); any other trajectory through its Euler view ``evaluate(t)``,
    ``omega_b = L(A) dA``, ``alpha_b = L(A) ddA + dL dA`` (defined at every angle: ``L`` is)."""
    from coopctrl.trajectory import GeodesicTrajectory

    times = np.asarray(times, dtype=float)
    if isinstance(trajectory, GeodesicTrajectory):
        m = trajectory.sample_rotation(times)
        return m.r, m.dr, m.ddr, quat.matrix(m.q), m.omega_body, m.alpha_body
    Y, dY, ddY = (np.array(v).reshape(len(times), 6) for v in
                  zip(*(trajectory.evaluate(float(t)) for t in times))) if len(times) else (np.zeros((0, 6)),) * 3
    A, dA, ddA = Y[:, 3:], dY[:, 3:], ddY[:, 3:]
    return (Y[:, :3], dY[:, :3], ddY[:, :3], rotations_of(A), body_rates(A, dA),
            body_rates(A, ddA) + rate_map_dot_times(A, dA))


def own_chart_table(motion) -> np.ndarray:
    """The kernel's trajectory table (3, N, 6) of ``motion`` (:func:`target_motion`), each row in the chart
    centred on its own target: ``A = 0``, ``dA = L(0)^-1 omega_b``, ``ddA = L(0)^-1 (alpha_b - dL(0, dA) dA)``
    (``L(0)`` the permutation (z, y, x)); positions as they are."""
    r, dr, ddr, _, w, a = motion
    N = r.shape[0]
    zero = np.zeros((N, 3))
    dA = w[:, ::-1].copy()
    ddA = (a - rate_map_dot_times(zero, dA))[:, ::-1]
    return np.ascontiguousarray(np.stack([np.hstack((r, zero)), np.hstack((dr, dA)), np.hstack((ddr, ddA))]))


def book_view(C, A, dA):
    """World ZYX angles and rates ``(A_w, dA_w)`` (N, 3) of angles ``A`` and rates ``dA`` (N, 3) taken in the
    charts ``C`` (N, 3, 3): ``R(A_w) = C R(A)``, ``dA_w = L(A_w)^-1 L(A) dA`` (:func:`euler_rates`)."""
    Rw = np.einsum("nij,njk->nik", C, rotations_of(A))
    Aw = euler_of(Rw)
    return Aw, euler_rates(Aw, body_rates(A, dA))


class LoopCharts:
    """The stored charts of one charted run: re-centres them between kernel calls, remembers them tick by
    tick, and gives the record back in the book's world coordinates.

    ``node_rows``: the kernel's packed node rows (``P[8]`` of the run, a copy owned by the run), updated
    in place at each re-centring."""

    def __init__(self, plant, node_rows: np.ndarray):
        self.plant = plant
        self.node_rows = node_rows
        self.nodes = plant._free_nodes()  # (node, slice of its 6 coordinates in z): object, contact points
        self.nz = plant.nz
        #: ``(first tick, charts (m + 1, 3, 3))`` of every chart in use, in order.
        self.history: list[tuple[int, np.ndarray]] = [(0, plant.elastic.charts.copy())]
        self.recentrings = 0

    def chart_cos(self, x) -> float:
        """The smallest ``|cos theta|`` of the stored charts' angles at ``x``."""
        return float(min(abs(np.cos(x[sl.start + 4])) for _, sl in self.nodes))

    def check(self, x: np.ndarray, k: int, plan=None) -> bool:
        """Re-centre the stored charts on the state ``x`` (updated in place) of tick ``k`` when their
        :meth:`chart_cos` is below :data:`RECENTRE_COS`; True if it did. ``plan``: the run's integration
        plan, whose Newton matrix (implicit schemes) was made in the old chart: it starts cold."""
        if self.chart_cos(x) >= RECENTRE_COS:
            return False
        self.plant, x_new = self.plant.recentred(x)
        x[:] = x_new
        self.node_rows[:] = self.plant._node_params
        _cold_start(plan)
        self.history.append((k, self.plant.elastic.charts.copy()))
        self.recentrings += 1
        return True

    def deformation(self, rec: dict, k0: int, k1: int, rho: np.ndarray, limit: float):
        """The kernel's deformation guard on the recorded ticks ``k0 .. k1 - 1`` of this chart (the kernel's
        own reads the object's frame as ``R(A)``, the book's; here ``R = C R(A)``):
        ``d_i = R^T (r_i - r_0) - rho_i`` [m] of every contact; ``(tick, contact, |d|)`` of the first tick
        where some ``|d_i| > limit``, else ``None``."""
        if k1 <= k0:
            return None
        nz = self.nz
        x = rec["x"][k0:k1]
        R = np.einsum("ij,njk->nik", self.history[-1][1][0], rotations_of(x[:, nz - 3:nz]))
        rel = rec["r_contacts"][k0:k1] - x[:, None, nz - 6:nz - 3]
        d = np.linalg.norm(np.einsum("nji,nmj->nmi", R, rel) - rho[None], axis=2)  # (ticks, m)
        worst = d.max(axis=1)
        over = np.flatnonzero(~(worst <= limit))
        if not over.size:
            return None
        j = int(over[0])
        return k0 + j, int(np.argmax(d[j])), float(worst[j])

    def charts_per_tick(self, N: int) -> np.ndarray:
        """The stored charts (N, m + 1, 3, 3) in use at ticks ``0 .. N - 1``."""
        out = np.empty((N,) + self.history[0][1].shape)
        for i, (k0, C) in enumerate(self.history):
            k1 = self.history[i + 1][0] if i + 1 < len(self.history) else N
            out[k0:k1] = C
        return out

    def book_record(self, rec: dict, motion) -> None:
        """Turn ``rec`` (``x`` in the charts of each tick) into the book's world coordinates in place: the
        object's and contact points' angles and rates (:func:`book_view`); ``Y0_nominal`` from the target
        ``motion`` (:func:`target_motion`); and ``rec["object_rotation"]``, the object's rotation as a unit
        quaternion ``(w, x, y, z)`` (N, 4) exact at every pitch (``q(C) q(A)``)."""
        x = rec["x"]
        N = x.shape[0]
        C = self.charts_per_tick(N)
        nz = self.nz
        for node, sl in self.nodes:
            a = slice(sl.start + 3, sl.stop)
            da = slice(nz + sl.start + 3, nz + sl.stop)
            if node == 0:
                qC = np.array([_quaternion(c) for c in C[:, 0]]) if N else np.zeros((0, 4))
                rec["object_rotation"] = quat.multiply(qC, quat.from_zyx(x[:, a])) if N else np.zeros((0, 4))
            x[:, a], x[:, da] = book_view(C[:, node], x[:, a], x[:, da])
        r, dr, _, R, w, _ = motion
        n = min(N, r.shape[0])
        Aw = euler_of(R[:n])
        rec["Y0_nominal"][:n] = np.hstack((r[:n], Aw))


def _quaternion(R) -> np.ndarray:
    """The unit quaternion ``(w, x, y, z)`` of a rotation matrix (Shepperd's method, ``w >= 0``)."""
    t = np.trace(R)
    if t > max(R[0, 0], R[1, 1], R[2, 2]):
        w = 0.5 * np.sqrt(1.0 + t)
        return np.array([w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w), (R[1, 0] - R[0, 1]) / (4 * w)])
    i = int(np.argmax(np.diag(R)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
    q = np.empty(4)
    q[0] = (R[k, j] - R[j, k]) / s
    q[1 + i] = 0.25 * s
    q[1 + j] = (R[j, i] + R[i, j]) / s
    q[1 + k] = (R[k, i] + R[i, k]) / s
    return q if q[0] >= 0 else -q


def _cold_start(plan) -> None:
    """Drop what an integration plan carries from step to step in the old chart's coordinates: the
    implicit schemes' Newton matrix and Jacobian (an explicit plan carries nothing but the step size)."""
    import coopctrl.integrators.adaptive_plans as adaptive_plans

    name = type(plan).__name__
    if name == "ImplicitPlan":
        plan.memo[0] = 0.0  # M is not kept (coopctrl.integrators.compiled: memo[0])
    elif name == "TRBDF2Plan":
        plan.memo[adaptive_plans.M_HAVE_J] = 0.0
        plan.memo[adaptive_plans.M_GH] = 0.0
