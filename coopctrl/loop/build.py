"""The one place where a closed loop becomes the compiled tick's model (:mod:`coopctrl.loop.model`, by name).

:func:`constants` builds, once per loop (and again when its steps or integrator change), what every run of it shares
(:class:`LoopConstants`: the plant's arrays, the grasps, the object, the QP's constants and row layout, the posture,
the steps); per run, :meth:`LoopConstants.control_model` reads the controllers by name,
:meth:`LoopConstants.options` what the run switches on, :func:`sensor_model` draws the sensor noise and
:func:`trajectory_samples` tabulates the nominal motion. Each reads the loop's parts through their public members.
:mod:`coopctrl.loop.run` drives the ticks on the model.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from coopctrl.integrators.methods import METHODS
from coopctrl.load_distribution.load_distribution import ANSWER_TOLERANCE_OF_LOAD
from coopctrl.loop.data import QPArrays
from coopctrl.loop.model import ControlModel, QPConstants, RunOptions, SensorModel


def inner(controller):
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
    kernel does not implement (such a loop cannot run: :func:`~coopctrl.loop.run.run_compiled` raises ``TypeError``)."""
    return integrator_outside(loop) or unsupported_parts(loop)


def unsupported_parts(loop) -> str | None:
    from coopctrl.controllers import FollowerForceController, GraspCompliance, LeaderController
    from coopctrl.sensors import SensorSuite
    from coopctrl.controllers.probes import FollowerProbe, LeaderProbe

    if (type(loop.leader) not in (LeaderController, LeaderProbe) or type(inner(loop.leader)) is not LeaderController
            or any(type(c) not in (FollowerForceController, FollowerProbe) or type(inner(c)) is not FollowerForceController
                   for c in loop.followers.values())):
        return "controllers other than LeaderController and FollowerForceController (or their tuning probes)"
    if type(loop.compliance) is not GraspCompliance or type(loop.sensors) is not SensorSuite:
        return "a grasp compliance or sensor suite of another type"
    if not callable(getattr(loop.trajectory, "evaluate", None)):
        return f"a trajectory of type {type(loop.trajectory).__name__} without evaluate(t)"
    return None


class LoopConstants:
    """What every run of one loop shares, by name: the plant's arrays, the grasps, the object, the QP's constants and
    layout, the posture and the integration steps (built once per loop and integrator, :func:`constants`)."""

    def __init__(self, loop):
        plant = loop.plant
        self.spatial = spatial = loop.space == "spatial"
        p = plant.p
        m = plant.arm_count
        self.P = plant.plant_args  # the plant kernels' arrays by name (PlantArgs)
        self.grasps = np.ascontiguousarray(loop.grasps, dtype=float)
        self.object_mass = float(loop.object_mass)
        self.object_inertia = np.ascontiguousarray(loop.object_inertia, dtype=float)
        self.rho = np.ascontiguousarray(loop.contact_points, dtype=float)
        fol = [inner(c) for c in loop.followers.values()]
        leader = inner(loop.leader)
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
        pb = loop.fresh_load_distribution().problem
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
        self.n_in = start
        self.rows = rows
        self.joint_counts = tuple(plant.arm_dofs)
        cos_phi = pb.cos_phi.ravel().copy() if spatial else np.zeros(1)
        sin_phi = pb.sin_phi.ravel().copy() if spatial else np.zeros(1)
        tau_qp = np.concatenate([np.broadcast_to(t, (a.dof,)) for t, a in zip(loop.qp_torque_limits, plant.arms)])
        self.qp = QPConstants(
            W_diag=pb.W_diag.copy(), W_inv_diag=pb.W_inv_diag.copy(), s_des=pb.s_des.copy(), tau_qp=tau_qp.astype(float),
            tau_max=loop.tau_max.astype(float), cos_phi=cos_phi, sin_phi=sin_phi, eps_abs=float(cfg.eps_abs),
            mu_c=float(pb.mu_c), max_iter=int(cfg.max_iter),
            min_grip=float(cfg.min_grip) if cfg.min_grip is not None else 0.0, answer_rho=ANSWER_TOLERANCE_OF_LOAD,
            has_squeeze=bool(pb.has_squeeze), min_grip_row=rows.get("min_grip", -1),
            friction_row=rows.get("friction", -1), torque_row=rows.get("torque_limits", -1), facets=int(nf),
            max_consecutive_failures=int(cfg.max_consecutive_failures))
        self.n = n
        self.npairs = pb.E.shape[1]
        self.problem = pb
        self.ld_config = cfg
        self.method = METHODS.get(getattr(loop.integrator, "name", None), -1)
        self.plant_outside = integrator_outside(loop) is not None
        self.steps = np.array(loop.steps, dtype=float)
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
        M[:p] = pb.identity_grasp
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

        leader = inner(loop.leader)
        return loop.leader_law if loop.leader_law is not None else computed_torque(leader.Kp, leader.Kd)

    def control_model(self, loop) -> ControlModel:
        """The run's controllers by name, as the tick reads them (:class:`~coopctrl.loop.model.ControlModel`): the
        leader's and the followers' gains, the posture, the compliances, and the leader's and the followers' laws (a
        built-in law by its name, a law written in Python as its function: the slower path)."""
        from coopctrl.controllers.leader_law import computed_torque_law, object_impedance_law

        names = {computed_torque_law: "computed_torque", object_impedance_law: "object_impedance"}
        leader = inner(loop.leader)
        f = next((inner(c) for c in loop.followers.values()), None)
        Kp_f, Kd_f = (float(f.Kp), float(f.Kd)) if f else (0.0, 0.0)
        laws = {}
        for role, law in (("leader", self.leader_law(loop)), ("follower", getattr(loop, "follower_law", None))):
            if law is None:  # the followers' own computed torque with their gains
                laws[role], laws[f"{role}_params"] = "computed_torque", np.array([Kp_f, Kd_f], dtype=float)
            else:
                laws[role] = names.get(law.function, law.function)
                laws[f"{role}_params"] = law.param_array
        gain, q_rest = self.posture
        return ControlModel(leader=int(leader.index), leader_Kp=float(leader.Kp), leader_Kd=float(leader.Kd),
                            follower_kp=float(f.kp) if f else 0.0, follower_ki=float(f.ki) if f else 0.0,
                            follower_Kp=Kp_f, follower_Kd=Kd_f, force_loop=bool(f.force_loop) if f else False,
                            integral_limit=float(f.integral_limit) if f else 0.0,
                            posture_gain=np.ascontiguousarray(gain, dtype=float),
                            q_rest=np.ascontiguousarray(q_rest, dtype=float), compliance=self.C,
                            leader_law=laws["leader"], leader_law_params=laws["leader_params"],
                            follower_law=laws["follower"], follower_law_params=laws["follower_params"])


#: Each loop's constants, built at its first run (kept here, not on the loop: a run attaches
#: nothing to what it was given), dropped with the loop.
_COMPILED_LOOPS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def constants(loop) -> LoopConstants:
    """``loop``'s :class:`LoopConstants`, built at its first run and again when its steps or integrator change."""
    c = _COMPILED_LOOPS.get(loop)
    key = (tuple(loop.steps), getattr(loop.integrator, "name", None), id(loop.integrator))
    if c is None or c[0] != key:
        c = (key, LoopConstants(loop))
        _COMPILED_LOOPS[loop] = c
    return c[1]


def sensor_model(loop, N: int, plant, first: int = 0) -> SensorModel:
    """The sensors of a run (:class:`~coopctrl.loop.model.SensorModel`): the noise of ticks ``first .. N - 1``, drawn
    beforehand from fresh generators in the Python sensors' order (a continuation's from its first tick: the same
    draws as in one long run), and the quantization."""
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
    if first:  # the streams from the run's first tick
        noise_q, noise_o, noise_f = (a[first:] if a.shape[0] > 1 else a for a in (noise_q, noise_o, noise_f))
    # a noise-free channel: one row of zeros (the tick reads row 0)
    return SensorModel(joints=noise_q, object=noise_o, wrench=noise_f,
                       noisy_state=bool(state_noisy and (j.noise_std or j.quantization or o.noise_std or o.quantization)),
                       joint_step=float(j.quantization) if state_noisy else 0.0,
                       object_step=float(o.quantization) if state_noisy else 0.0, wrench_step=float(f.quantization))


def trajectory_samples(trajectory, times, p: int) -> np.ndarray:
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
