"""Run a :class:`~coopctrl.closed_loop.ClosedLoop` with the compiled tick (:class:`coopctrl._core.Tick`,
coopctrl/core/tick.h).

:func:`run_compiled` builds the kernel's constant arrays once per loop (:class:`CompiledLoop`),
a fresh :class:`~coopctrl.loop.state.LoopState` per run (so a run depends on ``x0`` and the
scenario only: the same loop run twice gives bit-identical records), calls the kernel, and turns
its stop code back into an exception, so the diagnosis of :meth:`ClosedLoop._stop_reason` runs
unchanged. A failed QP solve comes back to Python: the failure policy of
:class:`~coopctrl.load_distribution.LoadDistribution` (the infeasibility cause, hold the last
feasible split, give up after ``max_consecutive_failures``) is applied there and the kernel resumes
at the same tick.

Every run goes through the kernel's tick. The reference path (``load_distribution.solver`` other than
``"compiled"``) runs its two phases one tick at a time: the tick's sense phase assembles the QP in the arrays of a :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`,
:meth:`LoadDistribution.solve_assembled` solves it with the chosen backend (answer check, failure policy,
binding families, time per solve), and its act phase finishes the tick with the split
(``Tick.reference_step``). An integrator the kernel lacks (:func:`integrator_outside`) steps
the plant in Python between kernel calls (:data:`~coopctrl.loop.tick_codes.PLANT_EXTERNAL`). Passive runs,
``max_energy``, the elastic split and the tuning probes of :mod:`coopctrl.controllers.probes` are
kernel inputs (:meth:`CompiledLoop.options`).
"""

from __future__ import annotations

import math
import time as _time
import weakref

import numpy as np

from coopctrl.errors import DivergenceError, InfeasibleLoad, StepTooSmall
from coopctrl.integrators import ExplicitEuler
# the integrators the kernel implements, by name: the explicit ones share a compiled loop; the implicit
# ones (Newton in the kernel, their settings read from the integrator) another
from coopctrl.integrators.methods import METHODS
from coopctrl.load_distribution.load_distribution import ANSWER_TOLERANCE_OF_LOAD
import coopctrl._core as _core
import coopctrl.integrators.compiled as I
import coopctrl.loop.charts as loop_charts
from coopctrl.loop import step_budget as SB
from coopctrl.loop import tick_codes as K
from coopctrl.loop.squeeze import squeeze_workspace
from coopctrl.loop.data import LoopData, QPArrays, TickRecord
from coopctrl.loop.model import ControlModel, LoopModel, QPConstants, RunOptions
from coopctrl.loop.state import ChartState, LoopState
from plants.errors import EulerSingularityError, PlantError, SingularJacobianError

#: QP status names of the kernel's codes (as the compiled backend reports them).
_QP_STATUS = ("solved", "infeasible", "max_iter", "failed")

#: Ticks per kernel call: between calls Python runs its signal handlers (SIGINT, SIGTERM stop a run
#: within one chunk, tens of ms) and updates the progress bar.
_CHUNK = 500


def _inner(controller):
    """The controller a tuning probe wraps (or the controller itself)."""
    return getattr(controller, "inner", controller)


def integrator_outside(loop) -> str | None:
    """Why ``loop``'s plant integration cannot run in the kernel (``None``: it can): an integrator the
    kernel does not implement, stepped in Python between kernel calls (:data:`~coopctrl.loop.tick_codes.PLANT_EXTERNAL`)."""
    name = getattr(loop.integrator, "name", None)
    if name not in METHODS or type(loop.integrator).__module__.split(".")[1:2] != ["integrators"]:
        return f"integrator {name or type(loop.integrator).__name__!r} (compiled: {', '.join(METHODS)})"
    return None


def compiled_unsupported(loop) -> str | None:
    """What of ``loop`` does not run entirely in the kernel (``None``: everything does): an integrator
    the kernel lacks (the plant is then stepped in Python between kernel calls), or parts of types the
    kernel does not implement (such a loop cannot run: :func:`run_compiled` raises ``TypeError``)."""
    return integrator_outside(loop) or _unsupported_parts(loop)


def _unsupported_parts(loop) -> str | None:
    from coopctrl.controllers import FollowerForceController, GraspCompliance, LeaderController
    from coopctrl.sensors import SensorSuite
    from coopctrl.controllers.probes import FollowerProbe, LeaderProbe

    if (type(loop.leader) not in (LeaderController, LeaderProbe) or type(_inner(loop.leader)) is not LeaderController
            or any(type(c) not in (FollowerForceController, FollowerProbe) or type(_inner(c)) is not FollowerForceController
                   for c in loop.followers.values())):
        return "controllers other than LeaderController and FollowerForceController (or their tuning probes)"
    if type(loop.compliance) is not GraspCompliance or type(loop.sensors) is not SensorSuite:
        return "a grasp compliance or sensor suite of another type"
    if not callable(getattr(loop.trajectory, "evaluate", None)):
        return f"a trajectory of type {type(loop.trajectory).__name__} without evaluate(t)"
    return None


class CompiledLoop:
    """The kernel's constant arrays for one loop (plant tables, gains, QP structure)."""

    def __init__(self, loop):
        plant = loop.plant
        self.spatial = spatial = loop.space == "spatial"
        p = plant.p
        m = plant.arm_count
        self.P = plant.plant_args  # the plant kernels' arrays by name (PlantArgs)
        self.grasps = np.ascontiguousarray(loop.grasps, dtype=float)
        self.obj = np.concatenate([[loop.object_mass], loop.object_inertia]).astype(float)
        self.rho = np.ascontiguousarray(loop._rho, dtype=float)
        fol = [_inner(c) for c in loop.followers.values()]
        f = fol[0] if fol else None
        leader = _inner(loop.leader)
        self.ctrl = np.array([leader.index, leader.Kp, leader.Kd,
                              f.kp if f else 0.0, f.ki if f else 0.0, f.Kp if f else 0.0, f.Kd if f else 0.0,
                              float(f.force_loop) if f else 0.0, float(f.integral_limit) if f else 0.0])
        nmax = max([p] + list(plant.arm_dofs))
        q_rest = np.zeros((m, nmax))
        post = leader.posture
        for c in [leader] + fol:
            if c.posture.active:
                q_rest[c.index, :c.posture.n] = c.posture.q_rest
        self.posture = (np.array([post.Kp, post.Kd]), q_rest)
        self.C = np.ascontiguousarray(loop.compliance.C, dtype=float)
        # the QP's structure (LoadDistributionProblem's row layout)
        cfg = loop.ld.config
        pb = loop._fresh_load_distribution().problem
        n = pb.n
        fams = pb.families
        nf = pb.n_facets
        rows, start = {}, 0
        if "min_grip" in fams:
            rows["min_grip"] = start
            start += m
        if "friction" in fams:
            rows["friction"] = start
            start += m * nf
        if "torque_limits" in fams:
            rows["torque_limits"] = start
            start += int(sum(plant.arm_dofs))
        self.n_in = n_in = start
        self.rows = rows
        self.joint_counts = tuple(plant.arm_dofs)
        cos_phi = pb._cos_phi.ravel().copy() if spatial else np.zeros(1)
        sin_phi = pb._sin_phi.ravel().copy() if spatial else np.zeros(1)
        tau_qp = np.concatenate([np.broadcast_to(t, (a.dof,)) for t, a in zip(loop._qp_tau_max, plant.arms)]).astype(float)
        self.qp = QPConstants(
            W_diag=pb.W_diag.copy(), W_inv_diag=pb.W_inv_diag.copy(), s_des=pb.s_des.copy(), tau_qp=tau_qp,
            tau_max=loop.tau_max.astype(float), cos_phi=cos_phi, sin_phi=sin_phi,
            numbers=np.array([cfg.eps_abs, pb._mu_c, float(cfg.max_iter),
                              cfg.min_grip if cfg.min_grip is not None else 0.0, ANSWER_TOLERANCE_OF_LOAD]),
            rows=np.array([int(pb.has_squeeze), rows.get("min_grip", -1), rows.get("friction", -1),
                           rows.get("torque_limits", -1), nf, int(cfg.max_consecutive_failures)], dtype=np.int64))
        self.n = n
        self.npairs = pb.E.shape[1]
        self.problem = pb
        self.ld_config = cfg
        self.method = METHODS.get(getattr(loop.integrator, "name", None), -1)
        self.plant_outside = integrator_outside(loop) is not None
        self.steps = np.array(loop._steps, dtype=float)
        self.nmax = nmax
        self.external_qp = cfg.solver != "compiled"
        self.elastic = cfg.split == "elastic"
        self.K_obj = np.ascontiguousarray(loop.compliance.K, dtype=float)

    def qp_arrays(self, problem=None):
        """Fresh QP arrays (:class:`~coopctrl.loop.data.QPArrays`) with the fixed rows set.

        With ``problem`` (a fresh :class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`
        of the reference path, its torque rows allocated) ``M, lo, hi, H, g, external, F_pref`` are that
        problem's own arrays: the kernel assembles the QP in place and the backend reads it there."""
        p, n, n_in = (6 if self.spatial else 3), self.n, self.n_in
        if problem is not None:
            pb = problem
            return QPArrays(M=pb.M, lo=pb.lo, hi=pb.hi, H=pb.P, g=pb.g, x=np.zeros(n), z=np.zeros(p + n_in),
                            external=pb.external, F_pref=pb.F_pref, E=np.zeros((n, max(self.npairs, 1))),
                            A=np.zeros((p, p)), y=np.zeros(p), K=np.zeros((n, n)))
        pb = self.problem
        M = np.zeros((p + n_in, n))
        M[:p] = pb._G0
        lo = np.full(p + n_in, -np.inf)
        hi = np.full(p + n_in, np.inf)
        if "min_grip" in self.rows:
            lo[p + self.rows["min_grip"]:p + self.rows["min_grip"] + pb.m] = self.ld_config.min_grip
        if "friction" in self.rows:
            r = p + self.rows["friction"]
            hi[r:r + pb.m * pb.n_facets] = 0.0
        return QPArrays(M=M, lo=lo, hi=hi, H=np.diag(pb.W_diag), g=np.zeros(n), x=np.zeros(n), z=np.zeros(p + n_in),
                        external=np.zeros(n), F_pref=np.zeros(n), E=np.zeros((n, max(self.npairs, 1))),
                        A=np.zeros((p, p)), y=np.zeros(p), K=np.zeros((n, n)))

    def options(self, loop, rec, passive: bool) -> RunOptions:
        """The tick's :class:`~coopctrl.loop.model.RunOptions` of one run: what it switches on, the energy record,
        the elastic split's stiffness and the tuning probes' inputs as they are now."""
        from coopctrl.controllers.probes import FollowerProbe, LeaderProbe

        p, m = (6 if self.spatial else 3), self.K_obj.shape[0]
        lead_off = np.zeros(p)
        if isinstance(loop.leader, LeaderProbe):
            lead_off[:] = loop.leader.offset
        r, v, d = np.zeros((m, p)), np.zeros((m, p)), np.zeros((m, p), dtype=np.int64)
        g = np.ones((m, p))
        probes = False
        for i, c in loop.followers.items():
            if isinstance(c, FollowerProbe):
                probes = True
                r[i], v[i], g[i] = c.setpoint_offset, c.pi_output, c.error_gain
                d[i] = np.asarray(c.measurement_delay, dtype=np.int64)
        if np.any(d < 0):
            raise ValueError(f"FollowerProbe.measurement_delay = {d.tolist()}: expected integers >= 0 [ticks]")
        return RunOptions(passive=passive, energy=2 if loop.max_energy is not None else int(passive),
                          max_energy=float(loop.max_energy) if loop.max_energy is not None else math.inf,
                          elastic_split=self.elastic, probes=probes, plant_outside=self.plant_outside,
                          energy_record=rec["energy"], kinetic_energy_record=rec["kinetic_energy"], K_obj=self.K_obj,
                          leader_offset=lead_off, probe_offset=r, probe_pi=v, probe_gain=g, probe_delay=d)

    def leader_law(self, loop):
        """The leader's law of ``loop``: the user's, or the computed torque with the leader's gains."""
        from coopctrl.controllers.leader_law import computed_torque

        leader = _inner(loop.leader)
        return loop.leader_law if loop.leader_law is not None else computed_torque(leader.Kp, leader.Kd)

    def control_model(self, loop) -> ControlModel:
        """The run's controllers by name, as the tick reads them (:class:`~coopctrl.loop.model.ControlModel`): the
        gains, the posture, the compliances, and the leader's and the followers' laws (a built-in law by its name,
        a law written in Python as its function: the slower path)."""
        from coopctrl.controllers.leader_law import computed_torque_law, object_impedance_law

        names = {computed_torque_law: "computed_torque", object_impedance_law: "object_impedance"}
        (leader, Kp_l, Kd_l, kp_f, ki_f, Kp_f, Kd_f, force_loop, integral_limit) = self.ctrl
        gain, q_rest = self.posture
        laws = {}
        for role, law in (("leader", self.leader_law(loop)), ("follower", getattr(loop, "follower_law", None))):
            if law is None:  # the followers' own computed torque with their gains
                laws[role], laws[f"{role}_params"] = "computed_torque", np.array([Kp_f, Kd_f], dtype=float)
            else:
                laws[role] = names.get(law.function, law.function)
                laws[f"{role}_params"] = law.param_array
        return ControlModel(leader=int(leader), leader_Kp=float(Kp_l), leader_Kd=float(Kd_l), follower_kp=float(kp_f),
                            follower_ki=float(ki_f), follower_Kp=float(Kp_f), follower_Kd=float(Kd_f),
                            force_loop=bool(force_loop), integral_limit=float(integral_limit),
                            posture_gain=np.ascontiguousarray(gain, dtype=float),
                            q_rest=np.ascontiguousarray(q_rest, dtype=float), compliance=self.C,
                            leader_law=laws["leader"], leader_law_params=laws["leader_params"],
                            follower_law=laws["follower"], follower_law_params=laws["follower_params"])


#: Each loop's compiled constants, built at its first run (kept here, not on the loop: a run attaches
#: nothing to what it was given), dropped with the loop.
_COMPILED_LOOPS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _compiled(loop) -> CompiledLoop:
    c = _COMPILED_LOOPS.get(loop)
    key = (tuple(loop.steps), getattr(loop.integrator, "name", None), id(loop.integrator))
    if c is None or c[0] != key:
        c = (key, CompiledLoop(loop))
        _COMPILED_LOOPS[loop] = c
    return c[1]


def _noise(loop, N: int, plant):
    """The sensor noise of ``N`` ticks, drawn beforehand from fresh generators in the Python sensors' order."""
    sensors = loop.sensors.restarted()
    m, p, nz = plant.arm_count, plant.p, plant.nz
    nq = nz - p
    j, o, f = sensors.joints.config, sensors.object.config, sensors.forces.config
    state_noisy = not (j.is_exact and o.is_exact)
    noise_q = np.zeros((N if j.noise_std and state_noisy else 1, 2 * nq))
    if j.noise_std and state_noisy:
        raw = sensors.joints.rng.standard_normal((N, 2 * nq)) * j.noise_std  # per tick: arm by arm, q then dq
        col = 0
        for i in range(m):
            sl = plant.q_slice(i)
            ni = sl.stop - sl.start
            noise_q[:, sl] = raw[:, col:col + ni]
            noise_q[:, nq + sl.start:nq + sl.stop] = raw[:, col + ni:col + 2 * ni]
            col += 2 * ni
    noise_o = np.zeros((N if o.noise_std and state_noisy else 1, 2 * p))
    if o.noise_std and state_noisy:
        noise_o[:] = sensors.object.rng.standard_normal((N, 2 * p)) * o.noise_std
    noise_f = np.zeros((N if f.noise_std else 1, m * p))
    if f.noise_std:
        noise_f[:] = sensors.forces.rng.standard_normal((N, m * p)) * f.noise_std
    cfg = np.array([j.noise_std if state_noisy else 0.0, j.quantization if state_noisy else 0.0,
                    o.noise_std if state_noisy else 0.0, o.quantization if state_noisy else 0.0, f.quantization])
    return noise_q, noise_o, noise_f, cfg  # a noise-free channel: one row of zeros (the kernel reads row 0)


def _qp_failure(loop, cl: CompiledLoop, qa, code: int, iters: int, state: LoopState):
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
    ld = loop._fresh_load_distribution()
    pb = ld.problem
    if cl.joint_counts and "torque_limits" in cl.rows:
        pb._allocate(cl.joint_counts)
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
    state.ws[3][0] = 0  # cold start next time (CompiledSolver.reset)
    status, binding, detail, advice = ld._failure_cause(status, violated, tol)
    flags = state.flags
    flags.consecutive_failures += 1
    if not flags.have_last_split:
        raise InfeasibleLoad(status, binding, f"{detail}; first solve failed, no previous split to hold", advice)
    if flags.consecutive_failures >= cl.ld_config.max_consecutive_failures:
        raise InfeasibleLoad(status, binding, f"{detail}; {flags.consecutive_failures} consecutive failed solves",
                             advice)
    return status, binding


def _exception(loop, cl: CompiledLoop, code: int, k: int, stop, x_fail, traj, kb: int = 0):
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
            plant._check(np.array(stop.detail[:2], dtype=np.int64), x_fail)
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
    why = _unsupported_parts(loop)
    if why is not None:
        raise TypeError(f"the closed loop cannot run {why}: use the controllers, compliance, sensors and trajectory "
                        "that coopctrl.simulator.closed_loop builds")
    cl = _compiled(loop)
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
        ld = loop._fresh_load_distribution()  # cold, in a continuation too (its backend's state is not copied)
        if "torque_limits" in cl.rows:
            ld.problem._allocate(cl.joint_counts)
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
        traj = _trajectory_samples(loop.trajectory, times, p)
    noise_q, noise_o, noise_f, noise_cfg = _noise(loop, kb + N, plant)
    if kb:  # the streams from the run's first tick (the same draws as in one long run)
        noise_q, noise_o, noise_f = (a[kb:] if a.shape[0] > 1 else a for a in (noise_q, noise_o, noise_f))
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
                      obj=cl.obj, rho=cl.rho, max_deformation=loop.max_deformation, band=band,
                      control=cl.control_model(loop), qp=cl.qp, opts=opts, noise_q=noise_q, noise_o=noise_o,
                      noise_f=noise_f, noise_cfg=noise_cfg)
    tick = _core.Tick(model, data)  # the run's model and data read by name, once
    qp_solve_time = rec["qp_solve_time_s"]

    advance = tick.run_ticks  # ticks k0 .. k_stop - 1 (or to the end or an event)

    if cl.plant_outside and hasattr(loop.integrator, "reset") and start is None:
        loop.integrator.reset()  # a Python integrator's own state (a Newton matrix) starts afresh with the run
    steps, integrator_step = loop._steps, loop.integrator.step

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
            split = ld.solve_assembled(_moment_arms(qa.M, m, p, npos))
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
                    qstatus, binding = _qp_failure(loop, cl, qa, stop.detail[0], stop.detail[1], state)
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
                exc = _exception(loop, cl, code, k, stop, x_fail, traj, kb)
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
        status, reason = loop._stop_reason(exc, kb + k, k_done, rec, state.x, x_good, t_good, x0, events, saturation)
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
    statuses, bindings, counts = _qp_columns(qs[:0 if passive else k_done], qb, held, families, bits)
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


def _qp_columns(qs, qb, held: dict, families: list, bits: dict) -> tuple[list, list, dict]:
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


def _moment_arms(M, m: int, p: int, npos: int) -> np.ndarray:
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


def _trajectory_samples(trajectory, times, p: int) -> np.ndarray:
    """``(Y, dY, ddY)`` of the nominal object motion at ``times``, stacked (3, N, p) [m, rad, per s, per s^2], a new
    array: ``sample`` (vectorized) when the trajectory has it, computed once per shipped trajectory and times
    (:func:`coopctrl.derived.derived`), else ``evaluate`` tick by tick."""
    from coopctrl.derived import derived, immutable

    if not len(times):
        return np.zeros((3, 0, p))
    if immutable(trajectory):  # their sample() is evaluate() at every time
        times = np.array(times, dtype=float)

        def compute():
            table = np.ascontiguousarray(np.stack(trajectory.sample(times)))
            table.flags.writeable = False
            return table

        return derived(trajectory, ("samples", times.shape, times.tobytes()), compute).copy()
    out = np.empty((3, len(times), p))
    for k, t in enumerate(times):
        out[:, k] = trajectory.evaluate(float(t))
    return out
