"""Pre-flight: is the task possible at all? Checked along the nominal trajectory before any simulation.

At every via point, at every segment's closed-form acceleration and speed peaks
(:meth:`MinimumJerkTrajectory.peak_times <coopctrl.trajectory.MinimumJerkTrajectory.peak_times>`: a grid
misses the extremes of a segment shorter than its step), on a grid of :data:`GRID_INTERVALS` equal steps
from 0 to the last via point (at most :data:`SAMPLE_STEP` apart when that gives fewer) and at the end of
the run (the path holds its last pose from the last via point on: one sample checks it all), the nominal
object motion gives every contact node's nominal motion (148) and the external load ``w_N``; then, in
order:

1. **Reach.** Each arm must reach its node's nominal pose (rigid, then deformed by its planned
   wrench through the grasp compliance, as :meth:`ClosedLoop.loaded_state` places it) by inverse
   kinematics within its joint limits (residual at most ``IK_TOLERANCE``); the previous sample's
   joints seed the next, so the arm follows one branch (C++, :mod:`coopctrl.analysis.preflight_ik`;
   the arm's own random restarts when that seed does not converge).
2. **Load distribution.** The scene's QP (``G F = w_N``, squeeze, grip, friction, and the torque
   limits when enabled, planned within :data:`~coopctrl.loop.qp_inputs.TORQUE_HEADROOM` of them) must
   have a feasible split at the arms' nominal state.
3. **Torques.** The joint torques that split needs with the nominal accelerations,
   ``tau_i = J_i^T F_i + H_i qdd_i + h_i + J_i^T (W_i ddY_i + w_i)`` [N m], must lie within each
   joint's ``tau_max``.
4. **Static stability** (at the start and at every via point): the object's translational
   stiffness with the contact nodes held must be positive definite (a squeezed central-spring grasp
   buckles, docs/model.md s.3).

In the book's world angles the Euler band (a nominal path within 5 deg of pitch +-90 deg) is refused
earlier, as bad input (exit 2), when the loop is built; in rotation charts the checks run in the
book's angles through the band too (:func:`nominal_motion`), all but the instants within 0.06 deg
of pitch +-90 deg while the object turns (none sampled on the shipped paths). The first failure is reported with its time and what binds, e.g.
``at t = 0.42 s arm 2 joint 3 needs 187 N m > tau_max 97.6 N m``.

Cost: the number of samples is the via points, three peaks per segment, at most ``GRID_INTERVALS + 1``
grid points and the end, whatever the duration (:func:`sample_times`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from coopctrl._core import square_joint_rates_into
from coopctrl.analysis.preflight_ik import warm_ik
from coopctrl.compact_repr import compact_repr
from coopctrl.errors import CoopctrlError, InfeasibleLoad
from coopctrl.io.number_text import numbers_text
from coopctrl.load_distribution import LoadDistribution
from coopctrl.loop.diagnosis import static_instability
from coopctrl.loop.qp_inputs import TORQUE_HEADROOM, TorqueModel, contact_normals, qp_torque_limits
from plants.cooperative import ContactPoint
from plants.cooperative.control_terms import ControlTerms
from plants.errors import PlantError

#: Steps of the sampling grid from 0 to the last via point [-] (fewer when :data:`SAMPLE_STEP` apart gives
#: fewer): the samples between via points are bounded whatever the duration; a segment's extremes are its
#: closed-form peak instants, sampled too.
GRID_INTERVALS = 20
#: Smallest grid spacing [s]: a short path is not sampled more finely than this.
SAMPLE_STEP = 0.01


class ImpossibleTask(CoopctrlError, ArithmeticError):
    """Pre-flight found the task impossible (exit 1: the input is valid, the task is not).

    Attributes:
        issue: The first :class:`PreflightIssue` found.
    """

    def __init__(self, issue: "PreflightIssue"):
        self.issue = issue
        super().__init__(f"pre-flight: {issue.message}")


@dataclass(frozen=True)
class PreflightIssue:
    """One reason the task is impossible.

    Attributes:
        time_s: Time on the nominal trajectory [s].
        kind: ``"unreachable"``, ``"qp_infeasible"`` (no split exists), ``"qp_solver"`` (a split exists but
            the solver did not find it: its iteration limit, an inaccurate answer, a numerical failure),
            ``"torque"`` or ``"static_instability"``.
        message: One line, beginning with the time, naming what binds and how to fix it.
        arm: The arm (1-based, as in ``arms[i - 1]``), or ``None``.
        joint: The joint (1-based), or ``None``.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    time_s: float
    kind: str
    message: str
    arm: int | None = None
    joint: int | None = None


@dataclass(frozen=True)
class PreflightReport:
    """What pre-flight checked and found.

    Attributes:
        scenario: The scenario's name.
        samples: Number of instants checked.
        torque_ratio_max: Largest ``|tau_i| / tau_max_i`` [-] the planned split needs (``nan`` if no
            sample got that far), at ``torque_ratio_time_s`` [s].
        issues: The failures, the earliest first (pre-flight stops at the first).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    scenario: str
    samples: int
    torque_ratio_max: float = math.nan
    torque_ratio_time_s: float = math.nan
    issues: tuple[PreflightIssue, ...] = field(default_factory=tuple)

    @property
    def ok(self) -> bool:
        return not self.issues

    def raise_if_impossible(self) -> None:
        """Raise :class:`ImpossibleTask` with the first issue, if any."""
        if self.issues:
            raise ImpossibleTask(self.issues[0])


def sample_times(via_times, duration: float, peak_times=()) -> np.ndarray:
    """The instants pre-flight checks, sorted: every via time and every trajectory peak instant
    (``peak_times`` [s]) within ``[0, duration]`` [s], the end ``duration``, and a grid of
    ``n = min(GRID_INTERVALS, ceil(span / SAMPLE_STEP))`` equal steps on ``[0, span]``, with ``span`` the
    last via time (or ``duration`` if the run ends first): after it the minimum-jerk path holds its last
    pose, so the end checks the rest. At most ``len(via_times) + len(peak_times) + GRID_INTERVALS + 2``
    instants, whatever the duration."""
    end = float(duration)
    vias = [float(t) for t in via_times if 0.0 <= t <= end]
    peaks = [float(t) for t in peak_times if 0.0 <= t <= end]
    span = min(end, max((float(t) for t in via_times), default=end))
    n = min(GRID_INTERVALS, int(math.ceil(span / SAMPLE_STEP))) if span > 0 else 0
    grid = np.linspace(0.0, span, n + 1) if n else np.zeros(1)
    return np.unique(np.round(np.concatenate([grid, vias, peaks, [max(end, 0.0)]]), 12))


#: In charts, a sample whose object pitch is within this |cos theta| [-] of +-90 deg while the object turns is
#: skipped: its book's rates ``L(A)^-1 omega`` do not exist there (0.06 deg from the singularity; elsewhere
#: in the band they exist, conditioned like ``1/cos theta <= 1e3``, and the checks map them back).
TURNING_AT_SINGULARITY_COS = 1e-3


def nominal_motion(loop, t: float):
    """The nominal object motion ``(Y, dY, ddY)`` (6,) each at ``t`` [s] in the book's world angles, or ``None``
    where they do not exist. Outside the Euler band the trajectory's own view; inside it (a path in rotation
    charts) from its rotation and body rates (:func:`coopctrl.loop.charts.target_motion`): ``A = euler(R)``,
    ``dA = L(A)^-1 omega``, ``ddA = L(A)^-1 (alpha - dL dA)``; ``None`` within
    :data:`TURNING_AT_SINGULARITY_COS` of pitch +-90 deg while turning."""
    from coopctrl.loop import charts as loop_charts
    from coopctrl.trajectory import EulerViewError

    try:
        return loop.trajectory.evaluate(t)
    except EulerViewError:
        pass
    r, dr, ddr, R, w, a = loop_charts.target_motion(loop.trajectory, np.array([t]))
    A, dA, ddA = loop_charts.euler_motion(R, w, a)
    if abs(math.cos(A[0, 1])) < TURNING_AT_SINGULARITY_COS and np.any(w != 0.0):
        return None
    return np.concatenate([r[0], A[0]]), np.concatenate([dr[0], dA[0]]), np.concatenate([ddr[0], ddA[0]])


def nominal_motions(loop, times) -> dict:
    """:func:`nominal_motion` at every time of ``times`` [s], keyed by the time: the trajectory's Euler view of
    them all at once (``sample``) when it exists at each, else one by one."""
    from coopctrl.trajectory import EulerViewError

    times = np.asarray(times, dtype=float)
    if hasattr(loop.trajectory, "sample") and times.size:
        try:
            Y, dY, ddY = loop.trajectory.sample(times)
            return {float(t): (Y[k], dY[k], ddY[k]) for k, t in enumerate(times)}
        except EulerViewError:
            pass
    return {float(t): nominal_motion(loop, float(t)) for t in times}


def preflight(scenario, loop=None) -> PreflightReport:
    """Check the task of ``scenario`` along its nominal trajectory (module docstring).

    ``loop`` is the scenario's :class:`~coopctrl.closed_loop.ClosedLoop` (built when ``None``; building
    it refuses a path through the Euler band with a :class:`~coopctrl.errors.ScenarioError`).
    Returns the :class:`PreflightReport` (``report.raise_if_impossible()`` to stop on a failure).
    """
    from coopctrl.controllers import required_object_wrench
    from coopctrl.scenario import build
    from plants.cooperative import nominal_node_motion
    from plants.errors import UnreachablePoseError

    if loop is None:
        from coopctrl.wiring import closed_loop

        loop = closed_loop(scenario)
    plant = loop.plant
    if not scenario.controllers.enabled:  # a passive scene has no task to check
        return PreflightReport(scenario.name, 0)
    from coopctrl.analysis.gain_stability import check_gains

    check_gains(scenario)  # gains the sampled linear model shows unstable: bad input, before the task
    m, space = plant.arm_count, loop.space
    via_times = [v.time for v in scenario.trajectory.via]
    peaks = loop.trajectory.peak_times() if hasattr(loop.trajectory, "peak_times") else ()
    times = sample_times(via_times, scenario.simulation.duration, peaks)
    motion = nominal_motions(loop, np.unique(np.concatenate([times, via_times])))
    # the checks run in the book's angles: at every instant where they exist (in charts, all but the turning
    # instants within 0.06 deg of pitch +-90 deg)
    times = np.array([t for t in times if motion[float(t)] is not None])
    via_times = [t for t in via_times if motion[float(t)] is not None]
    peak_set = {round(float(t), 12) for t in peaks}
    check_static = {0.0, *[round(float(t), 12) for t in via_times]}
    x = np.array(build.unloaded_state(scenario), dtype=float)  # the IK seeds; the arms then follow the path
    tau_max = [np.asarray(a.tau_max, dtype=float) for a in plant.arms]
    worst, worst_t = math.nan, math.nan
    names = [f"arms[{i}]" for i in range(m)]

    def fail(issue):
        return PreflightReport(scenario.name, len(times), worst, worst_t, (issue,))

    solvers = [warm_ik(arm) for arm in plant.arms]
    slices = [plant.q_slice(i) for i in range(m)]

    def reach(i, target):
        arm = plant.arms[i]
        sl = slices[i]
        if isinstance(arm, ContactPoint):
            return np.asarray(target, dtype=float)
        if solvers[i] is not None:  # compiled, from the previous sample's joints (one branch)
            q = solvers[i](target, x[sl])
            if q is not None:
                return q
        else:
            try:  # the previous sample's joints first (one branch)
                return arm.inverse_kinematics(target, x[sl], seeds=0)
            except UnreachablePoseError:
                pass
        try:  # the arm's own solve: that seed, then its random restarts
            return arm.inverse_kinematics(target, x[sl])
        except UnreachablePoseError as exc:
            return exc

    # every waypoint first: an out-of-reach waypoint is named as such, not as what fails on the way to it
    x_start = x.copy()
    for t in sorted(set(float(v) for v in via_times if 0.0 <= v <= scenario.simulation.duration)):
        Y0N, dY0N, ddY0N = motion[t]
        Yn = nominal_node_motion(Y0N, dY0N, ddY0N, loop.grasps, space)[0]
        for i in range(m):
            q = reach(i, Yn[i + 1])
            if isinstance(q, Exception):
                return fail(_unreachable(t, i, names[i], Yn[i + 1], q, via_times))
            x[slices[i]] = q
    x = x_start

    F = None
    ld = LoadDistribution(loop.ld.config, space, m)  # warm started sample to sample; a failure is re-solved afresh
    control_terms = _ControlTermsAt(plant, slices)
    torques = TorqueModel(plant)  # one workspace: each sample's rows are used before the next sample's
    for t in times:
        t = float(t)
        Y0N, dY0N, ddY0N = motion[t]
        Yn, dYn, ddYn = nominal_node_motion(Y0N, dY0N, ddY0N, loop.grasps, space)
        w_N = required_object_wrench(space, loop.object_mass, loop.object_inertia, loop.gravity, Y0N, dY0N, ddY0N)
        for _ in range(2 if F is None else 1):  # the first sample: the rigid pose, then the deformed one
            issue, terms, jac, bias, split = _sample(loop, plant, ld, control_terms, torques, x, t, F, Y0N, dY0N, Yn,
                                                     dYn, ddYn, w_N, reach, names, via_times, tau_max)
            if issue is not None:
                return fail(issue)
            F = split.F
        # 3. static stability of the grasp (before the torques: a buckling grasp is the cause, whatever they are)
        if round(t, 12) in check_static:
            why = static_instability(loop, x)
            if why:
                return fail(PreflightIssue(t, "static_instability", f"at t = {t:.4g} s {why}"))
        # 4. the torques the split needs
        over = _worst_joint(plant, jac, bias, F, tau_max)
        if over is not None:
            i, j, need, ratio = over
            if not ratio <= worst:  # also the first (nan)
                worst, worst_t = ratio, t
            if ratio > 1.0:
                at = f"{t:.6g} s{_peak_note(t, via_times)}" if round(t, 12) in peak_set else f"{t:.4g} s"
                return fail(PreflightIssue(t, "torque", (
                    f"at t = {at} arm {i + 1} joint {j + 1} needs {need:.4g} N m > tau_max "
                    f"{tau_max[i][j]:.4g} N m (the planned split with the nominal accelerations); lower the payload "
                    f"(object.mass) or the trajectory's accelerations, or raise {names[i]}.tau_max"), i + 1, j + 1))
    return PreflightReport(scenario.name, len(times), worst, worst_t)


def _peak_note(t: float, via_times) -> str:
    """`` (the peak of segment trajectory.via[k-1] -> via[k])`` for a peak instant ``t`` [s]."""
    k = int(np.searchsorted(np.asarray(via_times, dtype=float), t, side="right"))
    return f" (a closed-form peak of the segment trajectory.via[{k - 1}] -> via[{k}])"


def _worst_joint(plant, jac, bias, F, limits):
    """``(arm, joint, |tau| [N m], |tau| / limit)`` of the joint nearest its limit under the split ``F``
    (``tau_i = J_i^T F_i + bias_i``), or ``None`` when no arm has joints. A joint without a positive limit
    binds first (ratio ``inf``); the first of equal ratios wins."""
    best = None
    for i, arm in enumerate(plant.arms):
        if isinstance(arm, ContactPoint):
            continue
        need = np.abs(jac[i].T @ F[i] + bias[i])
        limited = limits[i] > 0
        ratio = np.where(limited, need, np.inf) / np.where(limited, limits[i], 1.0)
        j = int(ratio.argmax())
        if best is None or ratio[j] > best[3]:
            best = (i, j, float(need[j]), float(ratio[j]))
    return best


class _ControlTermsAt:
    """``plant.control_terms(x)`` (one call of the compiled core; an Euler singularity raises the plant's error
    naming the node), with the arms' joint counts, slices and a work array of joint rates."""

    def __init__(self, plant, slices):
        self.plant, self.slices = plant, slices
        self.dofs = np.array([arm.dof for arm in plant.arms], dtype=np.int64)
        self.rates = np.empty((plant.arm_count, max(plant.p, int(self.dofs.max()))))  # joint rates, a work array

    def __call__(self, x):
        return self.plant.control_terms(x)


def _terms_with_velocities(plant, control_terms, x, dYn):
    """Control terms at ``x`` (``control_terms(x)``) with each arm's joint rates set to follow its node's
    nominal rate: ``J_i dq_i = dYn_i`` solved exactly where every ``J_i`` is square and regular, else in
    the least-squares sense."""
    nz = plant.nz
    x[nz:2 * nz - plant.p] = 0.0
    terms = control_terms(x)
    rates = control_terms.rates
    if square_joint_rates_into(terms.J, dYn, control_terms.dofs, rates):
        rates = [rates[i, :n] for i, n in enumerate(control_terms.dofs)]
    else:
        rates = [np.linalg.lstsq(terms.J[i, :, :n], dYn[i + 1], rcond=None)[0]
                 for i, n in enumerate(control_terms.dofs)]
    for sl, dq in zip(control_terms.slices, rates):  # after solving: terms.J is the workspace the next call overwrites
        x[nz:][sl] = dq
    return control_terms(x)


def _unreachable(t, i, name, target, exc, via_times) -> PreflightIssue:
    """The issue of arm ``i`` not reaching ``target`` at ``t``, naming the via point if ``t`` is one."""
    at_via = [k for k, tv in enumerate(via_times) if abs(tv - t) <= 1e-9]
    where = f" (waypoint trajectory.via[{at_via[0]}])" if at_via else ""
    pose = numbers_text(np.asarray(target, dtype=float))
    return PreflightIssue(t, "unreachable", (
        f"at t = {t:.4g} s{where} arm {i + 1} ({name}) cannot reach its node pose ({pose}) within its joint "
        f"limits (best inverse-kinematics residual {exc.residual:.3g}); move the waypoint, the grasp "
        f"({name}.grasp) or the arm base ({name}.base) closer"), i + 1)

def _sample(loop, plant, ld, control_terms, torques, x, t, F, Y0N, dY0N, Yn, dYn, ddYn, w_N, reach, names, via_times,
            tau_max):
    """Reach, then the load distribution (``ld``, the run's :class:`LoadDistribution`), at one instant:
    ``(issue or None, terms, jac, bias, split)``; ``x`` gets the arms' joints and rates. ``control_terms``:
    a :class:`_ControlTermsAt` of the plant; ``torques``: its :class:`~coopctrl.loop.qp_inputs.TorqueModel`."""
    nz, p, npos, space, m = plant.nz, plant.p, loop.npos, loop.space, plant.arm_count
    none = (None, None, None, None)
    # 1. reach: each node's pose deformed by the previous split (rigid before the first split)
    x[nz - p:nz] = Y0N
    x[2 * nz - p:] = dY0N
    for i in range(m):
        target = Yn[i + 1] if F is None else loop.compliance.deformation(i, F[i], Y0N, Yn[i + 1])
        q = reach(i, target)
        if isinstance(q, Exception):
            return (_unreachable(t, i, names[i], target, q, via_times), *none)
        x[control_terms.slices[i]] = q
    try:
        terms = _terms_with_velocities(plant, control_terms, x, dYn)
    except PlantError as exc:
        return (PreflightIssue(t, "unreachable", f"at t = {t:.4g} s the nominal state is singular: {exc}"), *none)
    # 2. the load distribution
    config = loop.ld.config
    kwargs = {}
    if config.min_grip is not None or config.friction_coefficient is not None:
        kwargs["normals"] = contact_normals(loop.plant, terms)
    jac, bias = torques(terms, ddYn)
    if loop.torque_limits:
        kwargs["jacobians"], kwargs["biases"], kwargs["tau_max"] = jac, bias, qp_torque_limits(plant)
    if config.split == "elastic":
        kwargs["K"] = loop.compliance.stiffness_world(Y0N)
    try:
        try:
            split = ld.solve(terms.Y[1:, :npos], terms.Y[0, :npos], w_N, **kwargs)
        except InfeasibleLoad:
            split = None
        if split is None or split.held:  # each failure on its own: a fresh solve says why (never a held split)
            split = LoadDistribution(config, space, m).solve(terms.Y[1:, :npos], terms.Y[0, :npos], w_N, **kwargs)
    except InfeasibleLoad as exc:
        if exc.status != "infeasible":  # a split exists: the solver failed (its limit, its accuracy), say so
            return (PreflightIssue(t, "qp_solver", f"at t = {t:.4g} s {exc}"), *none)
        fams = ", ".join(exc.binding) or "unknown"
        binds, over = "", None
        if loop.torque_limits:  # which joint: the split without the torque rows, against the limits
            free = {k: v for k, v in kwargs.items() if k not in ("jacobians", "biases", "tau_max")}
            try:
                free_ld = LoadDistribution(replace(config, torque_limits=False), space, m)
                F_free = free_ld.solve(terms.Y[1:, :npos], terms.Y[0, :npos], w_N, **free).F
                over = _worst_joint(plant, jac, bias, F_free, [TORQUE_HEADROOM * lim for lim in tau_max])
            except InfeasibleLoad:
                over = None
            if over is not None and over[3] > 1.0:
                i, j, need, _ = over
                binds = (f"; without the torque limits arm {i + 1} joint {j + 1} needs {need:.4g} N m > "
                         f"{TORQUE_HEADROOM * tau_max[i][j]:.4g} N m ({TORQUE_HEADROOM:g} tau_max, the headroom the QP "
                         "plans within)")
        arm_joint = (over[0] + 1, over[1] + 1) if binds else (None, None)
        return (PreflightIssue(t, "qp_infeasible", (
            f"at t = {t:.4g} s the load distribution has no feasible split (status '{exc.status}', binding: "
            f"{fams}){binds}; reduce the payload (object.mass) or the acceleration of the trajectory, or relax "
            "those constraints"), *arm_joint), *none)
    return None, terms, jac, bias, split
