"""The closed loop in rotation charts (``scene.rotations = "charts"``; docs/model.md s.2, the loop in charts).

The loop runs in a *world chart*: a world frame turned by a rotation ``C`` that is re-centred on the object
whenever the object's ZYX angles in it near their singularity. Every quantity fixed in the world is taken
in the turned frame, ``v' = C^T v``: node positions and velocities, the plant's gravity and arm bases, the
trajectory's targets, the followers' force integrals and the held split; every node's angles are the ZYX
angles of ``C^T R``. Because the system is invariant under a rotation of the world ((4.7): geodesic
springs, frame-invariant dampers, isotropic central stiffness), the turned system is the book's system
with identity charts, so the compiled tick (plant, nominal motion (148), load split, controllers, guards)
runs unchanged and allocation-free; only arrays change, in place, between kernel calls
(:class:`WorldChart`). Right after a re-centring the object is at ``A' = 0`` and each contact node at its
grasp's angles (a scene's grasps are away from pitch 90 deg), so no node nears the singularity.

Why ``RECENTRE_COS = 0.7`` (45.6 deg from the chart's centre): there ``1/cos(theta)``, the growth of
``L^-1`` and of the fastest rotational mode (docs/model.md s.2), is at most 1.43, so the chart never costs
more than that factor in conditioning, while a re-centring (a few 3x3 products, exact up to rounding) is
needed once per 45 deg of turn. Each kernel call runs as many ticks as the object needs, at twice its
present angular speed, to turn from its pitch to 55 deg (:meth:`WorldChart.ticks_ahead`, 20 to 500
ticks: a call's entry costs about 0.1 ms), so the conditioning stays below 1.74; the kernel's Euler band
guard (5 deg, in the turned frame) stops a much faster turn with its cause.

After the run the record is turned back into the book's world coordinates (:meth:`WorldChart.book_record`),
with the object's rotation kept exactly as a quaternion (``object_rotation``).

Chosen over the plant's per-node charts (``CooperativePlant(arm_charts="own")`` and stored charts), which
need every controller kernel to read each node's chart (targets as ``euler(C_k^T R)``, ``C_k R(A)`` in the
pose increments, contact normals, torque rows and the elastic split): the world chart gives the same
singularity-free loop with no change to the compiled tick, so every shipped scene stays bit-identical and
the tick's speed unchanged. The controllers' Euler-coordinate laws then act on the turned frame's angles,
which near ``A' = 0`` are the body rotation's (as per-body charts would give).
"""

from __future__ import annotations

import math

import numpy as np

import coopctrl.trajectory.quaternion as quat
from coopctrl.load_distribution.goldfarb_idnani import gi_cold_start
from plants.frames import EULER_SINGULARITY_COS

#: Re-centre the stored charts below this smallest ``|cos theta|`` [-] (module docstring: why 0.7).
RECENTRE_COS = 0.7
#: Fewest and most ticks per kernel call of a run in charts (how often the chart is checked; module docstring).
CHART_CHUNK = 20
CHART_CHUNK_MAX = 500
#: The object's pitch in the world chart that a kernel call may not reach [rad]: 10 deg past the re-centring
#: bound (45.6 deg), so the chart's conditioning 1/cos(theta) stays below 1.74.
CHART_PITCH_MAX = math.radians(55.0)


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


def euler_motion(R, w, a) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ZYX angles, rates and accelerations ``(A, dA, ddA)`` (N, 3) of rotations ``R`` (N, 3, 3) turning at body
    rates ``w`` [rad/s] and accelerations ``a`` [rad/s^2] (N, 3): ``A = euler(R)``, ``dA = L(A)^-1 w``,
    ``ddA = L(A)^-1 (a - dL(A, dA) dA)`` (:func:`euler_rates`: finite at the singularity itself)."""
    A = euler_of(R)
    dA = euler_rates(A, w)
    return A, dA, euler_rates(A, a - rate_map_dot_times(A, dA))


def target_motion(trajectory, times):
    """The nominal object motion at ``times`` (N,) [s] on the rotation group: ``(r, dr, ddr, R, omega_b,
    alpha_b)``, positions [m, m/s, m/s^2] (N, 3), rotations (N, 3, 3), body angular velocity [rad/s] and
    acceleration [rad/s^2] (N, 3). A :class:`~coopctrl.trajectory.GeodesicTrajectory` (any trajectory with
    ``sample_rotation``) gives it at every rotation; any other through its Euler view ``evaluate(t)``,
    ``omega_b = L(A) dA``, ``alpha_b = L(A) ddA + dL dA`` (defined at every angle: ``L`` is). For a shipped
    trajectory computed once per trajectory and times (:func:`coopctrl.derived.derived`): the arrays
    are read-only."""
    from coopctrl.derived import derived

    times = np.array(times, dtype=float)

    def compute():
        motion = _target_motion(trajectory, times)
        for v in motion:
            v.flags.writeable = False
        return motion

    return derived(trajectory, ("target_motion", times.shape, times.tobytes()), compute)


def _target_motion(trajectory, times):
    """:func:`target_motion`, computed."""
    from coopctrl.trajectory import MinimumJerkTrajectory

    if hasattr(trajectory, "sample_rotation"):  # a path on the rotations (GeodesicTrajectory, or one read later)
        m = trajectory.sample_rotation(times)
        return m.r, m.dr, m.ddr, quat.matrix(m.q), m.omega_body, m.alpha_body
    if type(trajectory) is MinimumJerkTrajectory and len(times):  # its sample() is evaluate() at every time
        Y, dY, ddY = trajectory.sample(times)
    else:
        Y, dY, ddY = (np.array(v).reshape(len(times), 6) for v in
                      zip(*(trajectory.evaluate(float(t)) for t in times))) if len(times) else (np.zeros((0, 6)),) * 3
    A, dA, ddA = Y[:, 3:], dY[:, 3:], ddY[:, 3:]
    return (Y[:, :3], dY[:, :3], ddY[:, :3], rotations_of(A), body_rates(A, dA),
            body_rates(A, ddA) + rate_map_dot_times(A, dA))


def continuous(A, start=None) -> np.ndarray:
    """ZYX angles ``A`` (N, 3) [rad] of a motion made continuous in time: each row the representative of
    its rotation nearest the previous row, ``(psi, theta, phi)`` or ``(psi + pi, pi - theta, phi + pi)``
    plus whole turns (the branch flips where a principal ``psi`` or ``phi`` jumps by about pi: at a
    passage through pitch +-90 deg); the first row nearest ``start`` (3,) when given."""
    A = np.array(A, dtype=float)
    if not A.shape[0]:
        return A
    if start is not None:  # the first row's branch and turns: those nearest start
        alt = np.array([A[0, 0] + np.pi, np.pi - A[0, 1], A[0, 2] + np.pi])
        dist = [np.sum(np.abs(np.angle(np.exp(1j * (c - start))))) for c in (A[0], alt)]
        first_flip = dist[1] < dist[0]
    else:
        first_flip = False
    jump = np.abs(np.angle(np.exp(1j * np.diff(A[:, 0])))) > 0.5 * np.pi
    flip = np.concatenate([[first_flip], first_flip ^ (np.cumsum(jump) % 2 == 1)])
    A[flip, 0] += np.pi
    A[flip, 1] = np.pi - A[flip, 1]
    A[flip, 2] += np.pi
    A[:, 0], A[:, 2] = np.unwrap(A[:, 0]), np.unwrap(A[:, 2])
    A[:, 1] = np.unwrap(A[:, 1])
    if start is not None:
        A += 2.0 * np.pi * np.round((np.asarray(start, dtype=float) - A[0]) / (2.0 * np.pi))
    return A


def book_view(C, A, dA, start=None):
    """World ZYX angles and rates ``(A_w, dA_w)`` (N, 3) of angles ``A`` and rates ``dA`` (N, 3) taken in the
    charts ``C`` (N, 3, 3): ``R(A_w) = C R(A)`` continuous in time (:func:`continuous`, the first row
    nearest ``start``), ``dA_w = L(A_w)^-1 L(A) dA`` (:func:`euler_rates`)."""
    Rw = C @ rotations_of(A)  # batched 3x3 products (matmul: several times faster than einsum here)
    Aw = continuous(euler_of(Rw), start)
    return Aw, euler_rates(Aw, body_rates(A, dA))


def check_nominal_path_in_charts(trajectory, grasps) -> None:
    """Raise :class:`~coopctrl.errors.ScenarioError` if a contact node's angles in the world chart enter the
    Euler band (5 deg from pitch +-90 deg) on the nominal path (its vias' span: the object rests after).

    The world chart is centred on the object, and every contact node's angles are taken in it: a node at
    grasp angles ``A_g`` is at ``euler(C^T R_0 R(A_g))``. Along the nominal object rotations ``R_0(t)`` the
    chart is re-centred (``C = R_0``) when the object's pitch in it passes 45.6 deg (:data:`RECENTRE_COS`), or
    in a run as late as :data:`CHART_PITCH_MAX` (55 deg): both sequences are checked, every 0.25 deg of the
    object's turn (at least 200 samples per segment). The error names ``arms[k].grasp`` (per-node charts for
    contact nodes are not implemented: docs/model.md s.2). A shipped trajectory's path passed with these grasps
    is not checked again (:func:`coopctrl.derived.derived`)."""
    from coopctrl.derived import derived

    grasps = np.array(np.atleast_2d(np.asarray(grasps, dtype=float)))
    derived(trajectory, ("charts_path_passed", grasps.shape, grasps.tobytes()),
            lambda: _check_nominal_path_in_charts(trajectory, grasps))


def _check_nominal_path_in_charts(trajectory, grasps) -> None:
    """:func:`check_nominal_path_in_charts`, checked."""
    from coopctrl.errors import ScenarioError
    from coopctrl.loop.euler_band import margin_cos
    from plants.frames import rotation_zyx

    G = np.stack([rotation_zyx(np.ascontiguousarray(g[3:6])) for g in grasps])  # (m, 3, 3)
    ends = np.asarray(trajectory.times, dtype=float)
    t = np.unique(np.concatenate([np.linspace(a, b, 200) for a, b in zip(ends[:-1], ends[1:])] or [ends[:1]]))
    R = target_motion(trajectory, t)[3]
    turn = np.degrees(np.arccos(np.clip((np.einsum("nij,nij->n", R[1:], R[:-1]) - 1.0) / 2.0, -1.0, 1.0)))
    if turn.size and np.max(turn) > 0.25:  # finer where the object turns fast: 0.25 deg per sample at most
        t = np.unique(np.concatenate([np.linspace(a, b, int(math.ceil(d / 0.25)) + 1)
                                      for a, b, d in zip(t[:-1], t[1:], turn)]))
        R = target_motion(trajectory, t)[3]
    limit = margin_cos()
    for recentre in (RECENTRE_COS, math.cos(CHART_PITCH_MAX)):
        C, n0 = np.eye(3), 0
        while n0 < t.size:  # one batch per chart: up to the sample that re-centres it
            Rc = C.T @ R[n0:]
            moved = np.nonzero(np.sqrt(np.maximum(1.0 - Rc[:, 2, 0] ** 2, 0.0)) < recentre)[0]
            end = int(moved[0]) if moved.size else Rc.shape[0]
            s = np.clip(-(Rc[:end, 2, :] @ G[:, :, 0].T), -1.0, 1.0)  # (samples, m): each node's sin(pitch)
            cos = np.sqrt(np.maximum(1.0 - s * s, 0.0))
            if cos.size and np.min(cos) < limit:
                n, j = np.unravel_index(int(np.argmin(cos)), cos.shape)
                raise ScenarioError(
                    f"arms[{j}].grasp", [float(v) for v in grasps[j]],
                    f"a grasp whose contact node keeps its ZYX pitch at least 5 deg from +-90 deg in the world "
                    f"chart centred on the object (scene.rotations = 'charts': a contact node's angles are taken in "
                    f"the object's chart, docs/model.md s.2): on the nominal path contact node {j + 1} reaches "
                    f"pitch {math.degrees(math.asin(s[n, j])):.2f} deg at t = {t[n0 + n]:.4g} s; choose the grasp's "
                    f"node frame (its angles, with the arm's tool) so that its x axis stays away from the vertical "
                    f"on this path, e.g. along the axis the object turns about (per-node charts for contact nodes "
                    f"are not implemented)")
            if end == Rc.shape[0]:
                break
            C, n0 = R[n0 + end], n0 + end  # re-centred on the object: its angles there are 0


def chart_table(traj: np.ndarray, motion, C: np.ndarray, k: int = 0) -> None:
    """Rows ``k ..`` of the kernel's trajectory table ``traj`` (3, N, 6) of the target ``motion``
    (:func:`target_motion`) in the world chart ``C`` (:meth:`WorldChart.table`)."""
    r, dr, ddr, R, w, a = (v[k:] for v in motion)
    traj[0, k:, :3], traj[1, k:, :3], traj[2, k:, :3] = r @ C, dr @ C, ddr @ C
    traj[0, k:, 3:], traj[1, k:, 3:], traj[2, k:, 3:] = euler_motion(C.T @ R, w, a)


def world_table(trajectory, times) -> np.ndarray:
    """The kernel's trajectory table (3, N, 6) of the nominal motion at ``times`` (N,) [s] in the book's world,
    the first world chart (``C = I``; :func:`chart_table`): a new array, computed once per shipped trajectory and
    times (:func:`coopctrl.derived.derived`)."""
    from coopctrl.derived import derived

    times = np.array(times, dtype=float)

    def compute():
        table = np.zeros((3, times.shape[0], 6))
        chart_table(table, target_motion(trajectory, times), np.eye(3))
        table.flags.writeable = False
        return table

    return derived(trajectory, ("world_table", times.shape, times.tobytes()), compute).copy()


class WorldChart:
    """The rotated world of one run in charts: re-centres it between kernel calls, remembers it tick by
    tick, and gives the record back in the book's world coordinates (module docstring).

    ``P``: the run's plant arguments (:class:`~plants.cooperative.plant_args.PlantArgs`), whose ``P.bases`` and
    ``P.gravity`` are the run's own copies, rotated in place; ``arm_kind``, ``q_off``: which arms are contact points and where their
    coordinates are; ``nz``: the size of ``z``."""

    def __init__(self, P, nz: int, motion):
        self.P = P
        self.bases0 = P.bases.copy()
        self.gravity0 = P.gravity.copy()
        arm_kind, q_off = P.arm_kind, P.q_off
        #: Start in ``z`` of the object's and each contact point's 6 coordinates (a contact point's are its node's).
        self.free = [nz - 6] + [int(q_off[i]) for i in range(arm_kind.shape[0]) if arm_kind[i] == 1]
        #: Arm index -> start in ``z`` of a contact point (its input is a node force, rotated in the record).
        self.contact_points = {i: int(q_off[i]) for i in range(arm_kind.shape[0]) if arm_kind[i] == 1}
        self.nz = nz
        self.motion = motion
        self.C = np.eye(3)
        #: ``(first tick, C)`` of every world chart in use, in order.
        self.history: list[tuple[int, np.ndarray]] = [(0, self.C.copy())]

    def table(self, traj: np.ndarray, k: int) -> None:
        """Rows ``k ..`` of the kernel's trajectory table ``traj`` (3, N, 6) in the current world chart:
        ``r' = C^T r``, ``R' = C^T R``, ``A' = euler(R')``, ``dA' = L(A')^-1 omega_b``,
        ``ddA' = L(A')^-1 (alpha_b - dL(A', dA') dA')`` (the body rates do not depend on the chart)."""
        chart_table(traj, self.motion, self.C, k)

    def ticks_ahead(self, x: np.ndarray, T: float) -> int:
        """Ticks of period ``T`` [s] the next kernel call may run from the state ``x`` without the object's
        pitch in the world chart reaching :data:`CHART_PITCH_MAX` at twice its present angular speed:
        ``(CHART_PITCH_MAX - |theta'|) / (2 |omega| T)``, within ``CHART_CHUNK .. CHART_CHUNK_MAX``."""
        nz = self.nz
        th, ph = x[nz - 2], x[nz - 1]
        d = x[2 * nz - 3:2 * nz]
        cth, sth, cph, sph = math.cos(th), math.sin(th), math.cos(ph), math.sin(ph)
        w = math.sqrt((-sth * d[0] + d[2]) ** 2 + (sph * cth * d[0] + cph * d[1]) ** 2
                      + (cph * cth * d[0] - sph * d[1]) ** 2)  # |L(A) dA| [rad/s]
        budget = CHART_PITCH_MAX - abs(th)
        if not w * T * CHART_CHUNK_MAX * 2.0 > budget:
            return CHART_CHUNK_MAX
        return max(CHART_CHUNK, int(budget / (2.0 * w * T)))

    def check(self, x: np.ndarray, k: int, traj: np.ndarray, state, plan=None) -> bool:
        """Re-centre the world chart on the object when the ``|cos theta|`` of its angles at the state ``x``
        of tick ``k`` is below :data:`RECENTRE_COS`: ``C' = C R(A_0)``; the state, the plant's bases and
        gravity, the trajectory rows from ``k`` on, the followers' integrals and the last split (``state``,
        a :class:`~coopctrl.loop.state.LoopState`) rotated by ``D = C'^T C``; the QP and an implicit scheme
        start cold. True if it re-centred."""
        nz = self.nz
        A0 = x[nz - 3:nz]
        if abs(np.cos(A0[1])) >= RECENTRE_COS:
            return False
        Cn = self.C @ rotations_of(A0[None])[0]
        U, _, Vt = np.linalg.svd(Cn)  # re-orthonormalized (a product of many charts drifts by rounding)
        Cn = U @ Vt
        D = Cn.T @ self.C
        for s in self.free:
            r, A = x[s:s + 3], x[s + 3:s + 6]
            v, dA = x[nz + s:nz + s + 3], x[nz + s + 3:nz + s + 6]
            An = euler_of((D @ rotations_of(A[None])[0])[None])
            dAn = euler_rates(An, body_rates(A[None], dA[None]))
            x[s:s + 3], x[nz + s:nz + s + 3] = D @ r, D @ v
            x[s + 3:s + 6], x[nz + s + 3:nz + s + 6] = An[0], dAn[0]
        self._turn_world(Cn)
        for w in (state.integrals, *state.last_split):  # (m, 6) wrenches, force and moment rotated
            w[:, :3] = w[:, :3] @ D.T
            w[:, 3:] = w[:, 3:] @ D.T
        gi_cold_start(state.ws)  # the QP starts cold (CompiledSolver.reset): its warm start is in the old axes
        _cold_start(plan)
        self.C = Cn
        self.table(traj, k)
        self.history.append((k, Cn.copy()))
        return True

    def turn_to(self, C: np.ndarray) -> None:
        """Start in the world chart ``C`` (3, 3) (a run that continues one that ended in it): the plant's
        bases and gravity turned into it, as :meth:`check` turns them. Call before :meth:`table`."""
        self._turn_world(C)
        self.C = np.array(C, dtype=float)
        self.history = [(0, self.C.copy())]

    def _turn_world(self, C: np.ndarray) -> None:
        """The run's bases (``P.bases``) and gravity (``P.gravity``) in the world chart ``C``: ``C^T B``, ``C^T g``."""
        for i, B in enumerate(self.bases0):
            self.P.bases[i, :3, :3] = C.T @ B[:3, :3]
            self.P.bases[i, :3, 3] = C.T @ B[:3, 3]
        self.P.gravity[:] = C.T @ self.gravity0

    def _in_world(self, history=None) -> bool:
        """True while the run never left the book's world (one chart, the identity): nothing to turn back.
        ``history``: a part of :attr:`history` to ask about instead."""
        history = self.history if history is None else history
        return len(history) == 1 and np.array_equal(history[0][1], np.eye(3))

    def charts_per_tick(self, N: int) -> tuple[np.ndarray, np.ndarray]:
        """The world chart (N, 3, 3) in use at ticks ``0 .. N - 1`` and its quaternion (N, 4)."""
        out, q = np.empty((N, 3, 3)), np.empty((N, 4))
        for i, (k0, C) in enumerate(self.history):
            k1 = self.history[i + 1][0] if i + 1 < len(self.history) else N
            out[k0:k1] = C
            q[k0:k1] = _quaternion(C)
        return out, q

    def book_record(self, rec: dict, x0: np.ndarray) -> None:
        """Turn ``rec`` (in the world chart of each tick) into the book's world coordinates in place: its states
        and inputs (:meth:`book_rows`, continuous from the run's start ``x0``), the wrenches and contact
        positions (``C f``, ``C n``, ``C r``), ``Y0_nominal`` from the target motion, and
        ``rec["object_rotation"]``, the object's rotation as a unit quaternion ``(w, x, y, z)`` (N, 4) exact at
        every pitch (``q(C) q(A')``)."""
        x = rec["x"]
        N = x.shape[0]
        nz = self.nz
        if self._in_world():  # never re-centred: the world chart is the world (C = I), the record is the
            # book's already (the kernel's angles are continuous states) but for the object's rotation
            rec["object_rotation"] = quat.from_zyx(x[:, nz - 3:nz])
            return
        C, qC = self.charts_per_tick(N)
        rec["object_rotation"] = quat.multiply(qC, quat.from_zyx(x[:, nz - 3:nz]))
        # the rows before the first re-centring are in the world itself (C = I): kept as they are, bit for bit
        # the record of a run that never re-centred; the rest turned, continuous from the row before
        first = self.history[1][0] if self._in_world(self.history[:1]) else 0
        if first < N:
            self.book_rows(C[first:], x[first:], rec["tau"][first:], x[first - 1] if first else x0)
        for name in ("F_measured", "F_commanded", "F_external", "F_internal"):
            F = rec[name]
            F[:, :, :3], F[:, :, 3:] = _turned(C, F[:, :, :3]), _turned(C, F[:, :, 3:])
        rec["r_contacts"][:] = _turned(C, rec["r_contacts"])
        r, _, _, R, _, _ = self.motion
        n = min(N, r.shape[0])
        rec["Y0_nominal"][:n] = np.hstack((r[:n], euler_of(R[:n])))

    def book_rows(self, C, x, tau, start) -> None:
        """States ``x`` (N, nx) and inputs ``tau`` (N, nu), row ``n`` in the chart ``C[n]`` (N, 3, 3), turned back
        into the book's world coordinates in place: the object's and contact points' positions and velocities
        ``C r'``, their angles and rates by :func:`book_view` (continuous, the first row nearest ``start``
        (nx,)), a contact point's input (force ``C f'``, ``Q_A = L(A_w)^T L(A')^-T Q_A'``)."""
        nz = self.nz
        for s in self.free:
            A, dA = x[:, s + 3:s + 6].copy(), x[:, nz + s + 3:nz + s + 6]
            x[:, s:s + 3], x[:, nz + s:nz + s + 3] = _turned(C, x[:, s:s + 3]), _turned(C, x[:, nz + s:nz + s + 3])
            x[:, s + 3:s + 6], x[:, nz + s + 3:nz + s + 6] = book_view(C, A, dA, start[s + 3:s + 6])
            if s in self.contact_points.values():
                tau[:, s:s + 3] = _turned(C, tau[:, s:s + 3])
                body = np.linalg.solve(np.transpose(_rate_maps(A), (0, 2, 1)), tau[:, s + 3:s + 6, None])
                tau[:, s + 3:s + 6] = (np.transpose(_rate_maps(x[:, s + 3:s + 6]), (0, 2, 1)) @ body)[:, :, 0]

    def book_state(self, state, start: np.ndarray) -> None:
        """The loop state at the end of the run (``state``, a :class:`~coopctrl.loop.state.LoopState` in the
        last world chart ``C``) turned back into the book's world coordinates in place, as the record is: its
        state and held input by :meth:`book_rows` (nearest ``start`` (nx,), the run's last recorded state), the
        followers' integrals and the held split (force and moment rows ``C w'``). A run in charts thus ends in
        the coordinates it started in."""
        if self._in_world():  # never re-centred: C = I
            return
        C = self.C
        self.book_rows(C[None], state.x[None], state.tau[None], start)  # views: turned in place
        for w in (state.integrals, *state.last_split):  # (m, 6) wrenches, force and moment rows
            w[:, :3] = w[:, :3] @ C.T
            w[:, 3:] = w[:, 3:] @ C.T


def _turned(C, v) -> np.ndarray:
    """Rows turned by their tick's chart: ``C_n v_n`` for ``v`` (N, 3) or (N, m, 3), ``C`` (N, 3, 3)."""
    Cb = C if v.ndim == 2 else C[:, None]
    return (Cb @ v[..., None])[..., 0]


def _rate_maps(A) -> np.ndarray:
    """``L(A)`` (N, 3, 3) of ZYX angles ``A`` (N, 3) (docs/model.md s.2, (105))."""
    cth, sth = np.cos(A[:, 1]), np.sin(A[:, 1])
    cph, sph = np.cos(A[:, 2]), np.sin(A[:, 2])
    L = np.zeros((A.shape[0], 3, 3))
    L[:, 0, 0], L[:, 0, 2] = -sth, 1.0
    L[:, 1, 0], L[:, 1, 1] = sph * cth, cph
    L[:, 2, 0], L[:, 2, 1] = cph * cth, -sph
    return L


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
