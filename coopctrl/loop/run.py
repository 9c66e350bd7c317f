"""Run a :class:`~coopctrl.closed_loop.ClosedLoop` on the compiled tick (:class:`coopctrl._core.Tick`,
coopctrl/core/tick.h): chunks of ticks, the reference path, the QP's failure policy, the stop's exception.

:func:`run_compiled` builds the run's model (:mod:`coopctrl.loop.build`) and a fresh
:class:`~coopctrl.loop.state.LoopState` per run (so a run depends on ``x0`` and the scenario only: the same loop run
twice gives bit-identical records), calls the tick a chunk at a time, and turns its stop (``data.stop``, a
:class:`coopctrl._core.StopReport`) back into an exception (:func:`stop_exception`), so the diagnosis of
:meth:`ClosedLoop.stop_reason` runs on it. A failed QP solve comes back to Python: the failure policy of
:class:`~coopctrl.load_distribution.LoadDistribution` (the infeasibility cause, hold the last feasible split, give
up after ``max_consecutive_failures``) is applied there (:func:`qp_failure`) and the tick resumes at the same tick.

Every run goes through the tick. The reference path (``load_distribution.solver`` other than ``"compiled"``) runs
its two phases one tick at a time: the sense phase assembles the QP in the arrays of a
:class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`,
:meth:`LoadDistribution.solve_assembled` solves it with the chosen backend (answer check, failure policy, binding
families, time per solve), and the act phase finishes the tick with the split (``Tick.reference_step``). An
integrator the core lacks (:func:`~coopctrl.loop.build.integrator_outside`) steps the plant in Python between calls
(:data:`~coopctrl.loop.tick_codes.PLANT_EXTERNAL`). Passive runs, ``max_energy``, the elastic split and the tuning
probes of :mod:`coopctrl.controllers.probes` are model inputs (:meth:`LoopConstants.options`).
"""

from __future__ import annotations

import math
import time as _time

import numpy as np

from coopctrl.errors import DivergenceError, InfeasibleLoad, StepTooSmall
from coopctrl.integrators import ExplicitEuler
from coopctrl.load_distribution.goldfarb_idnani import gi_cold_start
import coopctrl._core as _core
import coopctrl.integrators.compiled as I
import coopctrl.loop.charts as loop_charts
from coopctrl.loop import step_budget as SB
from coopctrl.loop import tick_codes as K
from coopctrl.loop.build import LoopConstants, constants, sensor_model, trajectory_samples, unsupported_parts
from coopctrl.loop.squeeze import squeeze_workspace
from coopctrl.loop.data import LoopData, TickRecord
from coopctrl.loop.model import LoopModel
from coopctrl.loop.state import ChartState, LoopState
from plants.errors import EulerSingularityError, PlantError, SingularJacobianError

#: QP status names of the kernel's codes (as the compiled backend reports them).
_QP_STATUS = ("solved", "infeasible", "max_iter", "failed")

#: Ticks per kernel call: between calls Python runs its signal handlers (SIGINT, SIGTERM stop a run
#: within one chunk, tens of ms) and updates the progress bar.
_CHUNK = 500


def qp_failure(loop, cl: LoopConstants, qa, code: int, iters: int, state: LoopState):
    """Apply the load distribution's failure policy to a failed compiled solve (as
    :meth:`LoadDistribution.solve <coopctrl.load_distribution.LoadDistribution.solve>` does, on the
    kernel's problem arrays): the cause, then hold the last split or give up.

    Returns ``(status, binding)`` of the held split; raises :class:`InfeasibleLoad` when there is
    nothing to hold or ``max_consecutive_failures`` is reached."""
    if code == -1:
        raise InfeasibleLoad("failed", (), "degenerate grasp: the contacts do not span every object wrench",
                             "move the grasps apart")
    if code == -2:
        raise InfeasibleLoad("failed", (), "two contact points coincide", "move the grasps apart")
    if code == -3:
        raise InfeasibleLoad("failed", (), "the grasp stiffness is singular: the elastic split needs K^-1",
                             "use load_distribution.split = \"pseudo_inverse\", or interconnections stiff in every direction")
    ld = loop.fresh_load_distribution()
    pb = ld.problem
    if cl.joint_counts and "torque_limits" in cl.rows:
        pb.allocate(cl.joint_counts)
    M, lo, hi, H, g, x = qa.M, qa.lo, qa.hi, qa.H, qa.g, qa.x
    pb.M[:] = M
    pb.lo[:] = lo
    pb.hi[:] = hi
    pb.P = H
    pb.g[:] = g
    status = _QP_STATUS[code]
    violated: list[tuple[float, str]] = []
    tol = float("nan")
    if code != 3 and np.all(np.isfinite(x)):
        viol, scale = pb.max_violation(x)
        tol = ld.answer_tolerance(scale)
        if not viol <= tol:
            violated = sorted(((v, k) for k, v in pb.violations(x).items() if v > tol), reverse=True)
    gi_cold_start(state.ws)  # the next solve starts cold (CompiledSolver.reset)
    status, binding, detail, advice = ld.failure_cause(status, violated, tol)
    flags = state.flags
    flags.consecutive_failures += 1
    if not flags.have_last_split:
        raise InfeasibleLoad(status, binding, f"{detail}; first solve failed, no previous split to hold", advice)
    if flags.consecutive_failures >= cl.ld_config.max_consecutive_failures:
        raise InfeasibleLoad(status, binding, f"{detail}; {flags.consecutive_failures} consecutive failed solves",
                             advice)
    return status, binding


def stop_exception(loop, cl: LoopConstants, code: int, k: int, stop, x_fail, traj, kb: int = 0):
    """The exception that names the kernel's stop ``code`` at tick ``k`` of a run whose first tick is ``kb``
    (what the plant, the guards and the controllers raise from Python), from its details in ``stop`` (the run's
    :class:`coopctrl._core.StopReport`)."""
    from coopctrl.loop.euler_band import NearSingularity as _NearSingularity
    from coopctrl.loop.euler_band import closest_to_singularity
    from plants.cooperative import nominal_node_motion
    from plants.frames import body_rate_map_inv

    plant = loop.plant
    t = (kb + k) * loop.T
    if code == K.NONFINITE:
        return DivergenceError(t, "state (non-finite)", float("nan"))
    if code == K.NEWTON_FAILED:  # the Python integrator's exception, from the step that failed
        return I.newton_failure(loop.integrator.name, cl.steps, stop)
    if code == K.STEP_TOO_SMALL:
        from coopctrl.loop.stiffest_mode import stiffest_mode

        name, omega = stiffest_mode(plant, x_fail)
        pose = x_fail[plant.nz - plant.p:plant.nz]
        step, time = stop.value
        return StepTooSmall(float(time), float(step), loop.integrator.min_step, loop.integrator.name,
                            name, omega, tuple(float(v) for v in pose))
    if code == K.DEFORMATION:
        return DivergenceError(t, f"deformation of contact {stop.detail[0]} [m]", float(stop.value[0]))
    if code == K.ENERGY:
        return DivergenceError(t, "energy [J]", float(stop.value[0]))
    if code == K.NEAR_SINGULARITY:
        return _NearSingularity(closest_to_singularity(plant.node_poses(x_fail).reshape(-1, plant.p), t))
    try:
        if code == K.PLANT_ERROR:
            if stop.detail[0] == -1:
                th = float(x_fail[plant.nz - 6 + 4])
                raise EulerSingularityError("object", th, float(np.cos(th)))
            plant.check_status(np.array(stop.detail[:2], dtype=np.int64), x_fail)
        elif code in (K.NOMINAL_SINGULAR, K.POSE_INCREMENT_SINGULAR):
            Yn = nominal_node_motion(traj[0, k], traj[1, k], traj[2, k], loop.grasps, loop.space)[0]
            i = stop.detail[0]
            if code == K.POSE_INCREMENT_SINGULAR:
                body_rate_map_inv(Yn[i + 1, 3:6], f"contact node {i + 1}")
        elif code == K.SINGULAR_JACOBIAN:
            i = stop.detail[0]
            raise SingularJacobianError(f"Jacobian of arm {i} ('{plant.arms[i].name}')", float("inf"))
    except PlantError as exc:
        return exc
    return PlantError(f"compiled tick stopped with code {code} at tick {k}")


def run_compiled(loop, rec: dict, x0, N: int, progress: bool = False, integrals=None,
                 start: LoopState | None = None) -> dict:
    """Run ``N`` ticks of ``loop`` from ``x0`` with the compiled tick; fills and returns ``rec``.
    ``integrals``: the followers' force-error integrals to start from (arm index -> (p,) [N s, N m s]);
    zero otherwise. ``start``: a :class:`~coopctrl.loop.state.LoopState` to continue from (a run's
    ``final_state``; ``x0`` and ``integrals`` are then unused): its ticks follow on from those of the run
    that ended there, as in one long run, and it is left unchanged."""
    plant = loop.plant
    why = unsupported_parts(loop)
    if why is not None:
        raise TypeError(f"the closed loop cannot run {why}: use the controllers, compliance, sensors and trajectory "
                        "that coopctrl.simulator.closed_loop builds")
    cl = constants(loop)
    wall0 = _time.perf_counter()
    m, p = plant.arm_count, plant.p
    npos = 3 if cl.spatial else 2
    if start is None:
        x0 = np.array(x0, dtype=float)
        state = LoopState.start(x0, plant.input_size, m, p, cl.n, p + cl.n_in)
        for i, value in (integrals or {}).items():
            state.integrals[i] = value
    else:  # a continuation: on a copy of the state it was given, its tallies afresh
        state = start.for_continuation()
        x0 = state.x.copy()  # in the book's world coordinates: the diagnosis' start, the record's continuity
    kb = state.tick  # the run's first tick, counted from the motion's start
    pending, state.flags.advance_first = bool(state.flags.advance_first), 0  # set again for the kernel's first call
    passive = not loop.enabled
    ld = None
    if cl.external_qp and not passive:  # the reference path: the kernel assembles, the chosen backend solves
        ld = loop.fresh_load_distribution()  # cold, in a continuation too (its backend's state is not copied)
        if "torque_limits" in cl.rows:
            ld.problem.allocate(cl.joint_counts)
    qa = cl.qp_arrays(ld.problem if ld is not None else None)
    # the integrator's work arrays and Newton state, cold (an integrator outside the kernel steps in Python:
    # the kernel stops before its plant block, and an explicit Euler plan only fixes the argument types)
    plan = state.plan
    if plan is None or cl.plant_outside:
        plan = I.make_plan(loop.integrator if not cl.plant_outside else ExplicitEuler(), plant.state_size, loop.T, kb + N)
    elif hasattr(plan, "stats"):  # an error-controlled scheme's per-tick statistics, row round(t / T)
        import coopctrl.integrators.adaptive_plans as adaptive_plans

        plan = plan._replace(stats=adaptive_plans.step_statistics(kb + N))
    if not cl.plant_outside:
        state.plan = plan
    opts = cl.options(loop, rec, passive)
    times = (kb + np.arange(N)) * loop.T
    P = cl.P
    charts = None
    next_check = None  # charts: the tick of the first chart check, where the run continued from has it
    rhs = plant.rhs
    if loop.rotations == "charts":  # the loop in a world chart re-centred between kernel calls (coopctrl.loop.charts)
        turned = plant.with_own_world()  # the run's own bases and gravity, turned in place with the chart
        P = P._replace(bases=turned.plant_args.bases, gravity=turned.plant_args.gravity)
        rhs = turned.rhs  # a Python integrator steps the same turned world as the kernel
        charts = loop_charts.WorldChart(P, plant.nz, loop_charts.target_motion(loop.trajectory, times))
        if state.chart is not None:  # continue in the chart the run ended in, from its state there
            cs = state.chart
            charts.turn_to(cs.C)
            state.x[:], state.tau[:], state.integrals[:], state.last_split[:] = cs.x, cs.tau, cs.integrals, cs.last_split
            next_check = max(cs.next_check - kb, 0)
            traj = np.zeros((3, N, p))
            charts.table(traj, 0)
        else:  # the first chart is the book's world
            traj = loop_charts.world_table(loop.trajectory, times)
    else:
        traj = trajectory_samples(loop.trajectory, times, p)
    sensors = sensor_model(loop, kb + N, plant, kb)
    qs = np.zeros(N, dtype=np.int64)
    qb = np.zeros(N, dtype=np.int64)
    x_good = state.x.copy()
    x_fail = state.x.copy()
    stop = _core.StopReport()
    held: dict[int, tuple[str, tuple[str, ...]]] = {}
    events: list[tuple[float, str, str]] = []
    from coopctrl.loop.euler_band import margin_cos

    band = margin_cos()  # charts: the band of the rotated world's angles (the object's is re-centred at 45.6 deg)
    sq = squeeze_workspace(m, npos, loop.squeeze_desired)  # the squeeze recorded per tick
    record = TickRecord(t=rec["t"], x=rec["x"], tau=rec["tau"], Y0_nominal=rec["Y0_nominal"], F_measured=rec["F_measured"],
                        F_commanded=rec["F_commanded"], F_external=rec["F_external"], F_internal=rec["F_internal"],
                        r_contacts=rec["r_contacts"], squeeze=rec["squeeze"], qp_status=qs, qp_binding=qb,
                        qp_iterations=rec["qp_iterations"], qp_active_rows=rec["qp_active_rows"])
    data = LoopData(plan=plan, qp_arrays=qa, ws=state.ws, sq=sq, x=state.x, tau=state.tau,
                    integrals=state.integrals, last_split=state.last_split, flags=state.flags,
                    saturated_joints=state.saturated_joints, hold=state.hold, record=record, x_good=x_good, x_fail=x_fail,
                    stop=stop)

    model = LoopModel(spatial=cl.spatial, N=N, k_base=kb, T=loop.T, steps=cl.steps, P=P, grasps=cl.grasps, traj=traj,
                      object_mass=cl.object_mass, object_inertia=cl.object_inertia, rho=cl.rho,
                      max_deformation=loop.max_deformation, band=band, control=cl.control_model(loop), qp=cl.qp,
                      opts=opts, sensors=sensors)
    tick = _core.Tick(model, data)  # the run's model and data read by name, once
    qp_solve_time = rec["qp_solve_time_s"]

    advance = tick.run_ticks  # ticks k0 .. k_stop - 1 (or to the end or an event)

    if cl.plant_outside and hasattr(loop.integrator, "reset") and start is None:
        loop.integrator.reset()  # a Python integrator's own state (a Newton matrix) starts afresh with the run
    steps, integrator_step = loop.steps, loop.integrator.step

    def step_period(x, t):
        """The plant over one control period from ``t`` with the held torques (ZOH), in Python."""
        for hs in steps:
            x = integrator_step(rhs, t, x, state.tau, hs)
            t += hs
        return x

    if pending and not cl.plant_outside:  # the kernel's first call advances the period the run it continues did not
        state.flags.advance_first = 1
    startup = _time.perf_counter() - wall0  # the run's set-up: its model, data and tick built
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=N - 1, unit="tick", desc=loop.name, leave=False, mininterval=0.2)
    status, reason = "ok", ""
    k = 0
    exc = None
    qp_time = 0.0
    # the step budget of an error-controlled scheme (coopctrl.loop.step_budget): counted between chunks
    budgeted = hasattr(plan, "stats") and not cl.plant_outside
    python_steps = cl.plant_outside and getattr(loop.integrator, "steps_taken", None) is not None
    spent, k_counted = 0, 0
    scheme = getattr(loop.integrator, "name", type(loop.integrator).__name__)

    def budget_chunk(k_now: int, ticks: int) -> int:
        """``ticks`` cut to about :data:`~coopctrl.loop.step_budget.CHECK_STEPS` steps at the rate so far."""
        if not budgeted or spent == 0:
            return ticks
        return max(1, min(ticks, int(SB.CHECK_STEPS * max(k_now, 1) / spent)))
    bits = {"min_grip": K.FAMILY_MIN_GRIP, "friction": K.FAMILY_FRICTION, "torque_limits": K.FAMILY_TORQUE}

    def reference_ticks(k0: int, k_stop: int) -> None:
        """Ticks ``k0 .. k_stop - 1`` (or to the end or an event) of the reference path, as ``Tick.run_ticks``
        runs them but with the chosen backend's solve between the two phases of each tick (one core entry
        a tick: ``Tick.reference_step``); ``stop`` as the kernel leaves it. A solve
        that gives up raises :class:`InfeasibleLoad` (``stop.tick``: its tick)."""
        nonlocal qp_time
        if state.flags.advance_first:  # the period the run it continues did not advance (the kernel does it)
            advance(0, 0)
            if stop.code != K.CHUNK_END:
                return
        k = k0
        if k >= N or k == k_stop:
            stop.code, stop.tick = (K.DONE if k >= N else K.CHUNK_END), k
            return
        code, P_changed = tick.reference_step(k - 1, False, 0, 0, 0, 0, True)  # phase 1 of tick k
        while code == K.DONE:
            if P_changed:
                ld.problem.P_changed = True
            split = ld.solve_assembled(moment_arms(qa.M, m, p, npos))
            qp_solve_time[k] = split.solve_time_s
            qp_time += split.solve_time_s
            st, iterations = _QP_STATUS.index(split.status), int(split.iterations)
            if split.held:
                held[k] = (split.status, split.binding)
                events.append(((kb + k) * loop.T, "qp_held", f"QP status '{split.status}' (binding: "
                               f"{', '.join(split.binding) or '-'}); holding the last feasible split"))
                source, binding = K.SPLIT_HELD, 0
            else:
                qa.x[:] = split.F.reshape(-1)
                source, binding = K.SPLIT_SOLVED, sum(bits[f] for f in split.binding)
            sense_next = k + 1 != k_stop  # (tick N - 1 is recorded, not advanced: no next tick to sense)
            code, P_changed = tick.reference_step(k, True, source, st, iterations, binding, sense_next)
            if code == K.RECORDED:
                stop.code, stop.tick = K.DONE, k
                return
            k += 1
            if code == K.DONE and not sense_next:
                stop.code, stop.tick = K.CHUNK_END, k
                return

    try:
        if pending and cl.plant_outside:  # the period the run it continues did not advance, in Python
            try:
                with np.errstate(over="ignore", invalid="ignore"):
                    state.x[:] = step_period(state.x, (kb - 1) * loop.T)
            except (DivergenceError, PlantError) as e:
                exc = e
        if exc is not None:
            k_stop = 0
        elif charts is None:
            chunk_end = 10 if budgeted else _CHUNK  # an error-controlled run measures its step rate first
        elif next_check is None:
            if charts.check(state.x, k, traj, state, plan):
                tick.world_moved()
            chunk_end = charts.ticks_ahead(state.x, loop.T)
        else:  # the chart check where the run continued from would have made it (the kernel stops there)
            chunk_end = next_check
        if exc is None:
            k_stop = min(chunk_end, N)  # the next chunk's end (the kernel also returns at each external QP or plant step)
        while exc is None:
            if ld is None:
                advance(k, k_stop)
            else:
                try:
                    reference_ticks(k, k_stop)
                except InfeasibleLoad as e:
                    exc = e
                    k = stop.tick
                    break
            code = stop.code
            k = stop.tick
            state.tick = k
            if code == K.CHUNK_END:
                if bar is not None:
                    bar.update(k - bar.n)
                if budgeted:  # the steps of the ticks since the last count (accepted and rejected)
                    rows = plan.stats[kb + k_counted:kb + k]
                    spent, k_counted = spent + int(rows[:, 0].sum() + rows[:, 1].sum()), k
                    if spent > SB.step_budget(k, SB.STEPS_PER_PERIOD):
                        exc = SB.StepBudgetExceeded((kb + k) * loop.T, spent, SB.step_budget(k, SB.STEPS_PER_PERIOD),
                                                    scheme, SB.STEPS_PER_PERIOD)
                        break
                if charts is not None and charts.check(state.x, k, traj, state, plan):  # between two whole ticks
                    tick.world_moved()  # the tick reads the turned bases and gravity
                    if cl.plant_outside and hasattr(loop.integrator, "reset"):
                        loop.integrator.reset()  # a Python integrator's Newton matrix was in the old axes
                chunk_end = k + budget_chunk(k, _CHUNK if charts is None else charts.ticks_ahead(state.x, loop.T))
                k_stop = min(chunk_end, N)
                continue
            if code == K.PLANT_EXTERNAL:  # the plant over the period of tick k - 1, by the Python integrator
                try:
                    with np.errstate(over="ignore", invalid="ignore"):  # a diverging state is caught by the guards
                        state.x[:] = step_period(state.x, (kb + k - 1) * loop.T)
                except (DivergenceError, PlantError) as e:
                    exc = e
                    k -= 1
                    break
                if python_steps and loop.integrator.steps_taken > SB.step_budget(k, SB.PYTHON_STEPS_PER_PERIOD):
                    exc = SB.StepBudgetExceeded((kb + k) * loop.T, loop.integrator.steps_taken,
                                                SB.step_budget(k, SB.PYTHON_STEPS_PER_PERIOD), scheme,
                                                SB.PYTHON_STEPS_PER_PERIOD)
                    k -= 1
                    break
                continue
            if code == K.QP_FAILED:
                try:
                    qstatus, binding = qp_failure(loop, cl, qa, stop.detail[0], stop.detail[1], state)
                except InfeasibleLoad as e:
                    exc = e
                    break
                held[k] = (qstatus, binding)
                events.append(((kb + k) * loop.T, "qp_held", f"QP status '{qstatus}' (binding: {', '.join(binding) or '-'}); "
                                                      "holding the last feasible split"))
                hold = state.hold
                hold.mode, hold.iterations, hold.binding = 1, stop.detail[1], 0
                hold.qp_status = _QP_STATUS.index(qstatus) if qstatus in _QP_STATUS else 3
                continue
            if code != K.DONE:
                exc = stop_exception(loop, cl, code, k, stop, x_fail, traj, kb)
            break
    finally:
        if bar is not None:
            bar.close()
    k_done = stop.ticks_recorded
    saturated = state.flags.saturated_ticks
    sat_first = float(state.flags.first_saturated * loop.T) if saturated else math.nan
    saturation = {"saturated_ticks": saturated, "saturated_joint_ticks": state.saturated_joints.copy(),
                  "saturation_first_time_s": sat_first,
                  "saturated_last_tick": state.flags.last_saturated - kb if saturated else -1}  # a record row
    if exc is not None:
        good = stop.last_good_tick
        t_good = (kb + good) * loop.T if good >= 0 else kb * loop.T
        status, reason = loop.stop_reason(exc, kb + k, k_done, rec, state.x, x_good, t_good, x0, events, saturation)
    wall = _time.perf_counter() - wall0 - startup
    for key, val in rec.items():
        if isinstance(val, np.ndarray):
            rec[key] = val[:k_done]
    # where a continuation starts: the tick after the last recorded one, whose period is yet to be advanced
    state.tick = kb + k_done
    state.flags.advance_first = int(k_done > 0)
    state.resumable = exc is None
    if charts is not None:  # the record in the book's world coordinates, the object's rotation exactly
        state.chart = ChartState(charts.C.copy(), state.x.copy(), state.tau.copy(), state.integrals.copy(),
                                 state.last_split.copy(), kb + chunk_end)
        charts.book_record(rec, x0)
        charts.book_state(state, rec["x"][-1] if len(rec["x"]) else x0)
        for k0, _ in charts.history[1:]:
            events.append(((kb + k0) * loop.T, "chart_recentred", "the world chart re-centred on the object "
                                                           f"(|cos theta| below {loop_charts.RECENTRE_COS:g})"))
        events.sort(key=lambda e: e[0])
    families = [name for name in ("min_grip", "friction", "torque_limits") if name in cl.rows]
    if passive:  # no QP ran: no split, no status
        for key in ("F_commanded", "F_external", "F_internal"):
            rec[key][:] = np.nan
    statuses, bindings, counts = qp_columns(qs[:0 if passive else k_done], qb, held, families, bits)
    if saturated:
        events.append((sat_first, "torque_saturation",
                       f"commanded torques clipped at their limits on {saturated} ticks from t = {sat_first:.4g} s"))
    # the loop state at the end (the followers' integrals are read by analysis code); the run wrote into
    # its own arrays only, so the controllers, x0 and the loop are as they were given
    rec.update(status=status, reason=reason, events=events, wall_time_s=wall, startup_s=startup,
               qp_time_s=qp_time if ld is not None or passive else math.nan,
               qp_binding_counts=counts, qp_status=statuses, qp_binding=bindings,
               rhs_evaluations=None if cl.plant_outside else stop.rhs_evaluations,
               integration_steps=plan.stats[kb:kb + k_done].copy() if hasattr(plan, "stats") else None,
               final_state=state, **saturation)
    return rec


def qp_columns(qs, qb, held: dict, families: list, bits: dict) -> tuple[list, list, dict]:
    """Per tick ``i < len(qs)``: the QP status name (``_QP_STATUS[qs[i]]``), the binding families joined by
    ``+`` (the bits ``qb[i]`` of ``families``), and per family the ticks on which it was binding, keyed in
    the order of each family's first binding tick; a tick in ``held`` (tick -> (status, families)) has
    the status and families held there instead."""
    n = len(qs)
    statuses = np.array(_QP_STATUS, dtype=object)[qs].tolist()
    names = np.array(["+".join(f for f in families if c & bits[f]) for c in range(8)], dtype=object)
    mask = sum(bits[f] for f in families)
    codes = qb[:n] & mask
    bindings = names[codes].tolist()
    binding = {f: (codes & bits[f]) != 0 for f in families}
    for i, (st, fam) in held.items():
        if i < n:
            statuses[i] = st
            bindings[i] = "+".join(fam)
            for f in fam:
                binding.setdefault(f, np.zeros(n, dtype=bool))
            for f, b in binding.items():
                b[i] = f in fam
    first = {f: int(np.argmax(b)) for f, b in binding.items() if b.any()}
    counts = {f: int(np.count_nonzero(binding[f])) for f in sorted(first, key=first.get)}
    return statuses, bindings, counts


def moment_arms(M, m: int, p: int, npos: int) -> np.ndarray:
    """``r_i - r_0`` (m, npos) [m] of the grasp matrix ``G = M[:p]`` the kernel assembled (the contact
    points of a reference-path split, relative to the object: all its squeeze needs)."""
    r = np.empty((m, npos))
    for i in range(m):
        c = p * i
        if p == 6:
            r[i] = (M[4, c + 2] * -1.0, M[5, c + 0] * -1.0, M[3, c + 1] * -1.0)
        else:
            r[i] = (M[2, c + 1], -M[2, c])
    return r
