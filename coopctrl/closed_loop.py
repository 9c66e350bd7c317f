"""The closed loop, wired in one place: plant, sensors, load distribution, leader, followers.

::

        +--------------------------------------------------------------------------+
        |  trajectory(t) --> nominal node motion (148) --> w_N (external load)      |
        |                                                     |                     |
        |  sensors(x) --> q, dq, Y_0, F_meas ----------> QP (G F = w_N, squeeze)    |
        |       ^                 |                           | F*                  |
        |       |                 +--> leader: computed torque on Y_v^N(F*_v)       |
        |       |                 +--> followers: force PI --> computed torque      |
        |       |                                             | tau (ZOH)           |
        |       +------------------ plant: x' = f(t, x, tau) <+  (substeps x h)     |
        +--------------------------------------------------------------------------+

The controller runs at the control period ``T``; the torques are held (zero-order hold) while
the plant is integrated with ``substeps`` fixed steps ``h = T / substeps`` of the chosen
integrator, or with a free step ``h <= T`` (:meth:`ClosedLoop.set_step`): ``floor(T / h)`` steps
of ``h`` and one shorter remainder step that lands on the next control instant. Divergence (a
non-finite state, a deformation beyond ``max_deformation``, an energy beyond ``max_energy``, or a
numerical failure of the plant) stops the run with a diagnostic naming the time, the quantity and
its causes checked against the run's evidence (:mod:`coopctrl.analysis.diagnosis`: static
instability, an unreachable pose, torque saturation, a held QP split, and the step, with a suggested
step only when the step is beyond the closed loop's predicted limit); it never runs on silently. A
spatial node whose pitch comes within
:data:`~coopctrl.analysis.euler_singularity.EULER_PITCH_MARGIN_DEG` of +-90 deg stops the run as
an Euler-angle singularity (and a nominal path that does is refused when the loop is built).
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.analysis.euler_singularity import (
    EULER_PITCH_MARGIN_DEG,
    SingularityHit,
    check_nominal_path,
    closest_to_singularity,
    fix_hint,
    margin_cos,
)
from coopctrl.controllers import required_object_wrench
from coopctrl.controllers.computed_torque import task_acceleration
from coopctrl.errors import DivergenceError
from coopctrl.load_distribution import grasp_matrix, internal_force_basis
from coopctrl.record_memory import check_record_fits
from plants.cooperative import ContactPoint, nominal_node_motion
from plants.errors import EulerSingularityError, PlantError
from plants.frames import body_rate_map, rotation_zyx


#: Fraction of each joint torque limit the load-distribution QP may plan with [-].
TORQUE_HEADROOM = 0.9

#: Control ticks before the failure at which a diverged run is diagnosed [-]: the state of the last
#: tick may already be far into the blow-up (an unstable mode grows geometrically), so its
#: linearization would not be the one that failed.
DIAGNOSIS_TICKS_BACK = 5


class ClosedLoop:
    """A fixed-step closed loop over a cooperative plant.

    Args:
        plant: The cooperative plant (simulated, and also the controllers' model).
        trajectory: Object trajectory with ``evaluate(t) -> (Y, dY, ddY)``.
        grasps: (m, p) grasp poses in the object frame, as the controllers know them.
        load_distribution: :class:`~coopctrl.load_distribution.LoadDistribution`.
        compliance: :class:`~coopctrl.controllers.GraspCompliance`.
        leader: :class:`~coopctrl.controllers.LeaderController`.
        followers: Mapping arm index -> :class:`~coopctrl.controllers.FollowerForceController`.
        sensors: :class:`~coopctrl.sensors.SensorSuite`.
        integrator: A fixed-step integrator (``step(f, t, x, u, h)``).
        control_period: ``T`` [s]; substeps: integration steps per period.
        step: Optional free plant step ``h`` [s], ``0 < h <= T``, instead of ``T / substeps``
            (see :meth:`set_step`).
        squeeze_desired: (n_pairs,) desired virtual-linkage squeeze [N].
        max_deformation: Divergence bound on any node's displacement from its rigid pose [m].
        max_energy: Optional bound on the total energy [J].
    """

    def __init__(self, plant, trajectory, grasps, load_distribution, compliance, leader, followers, sensors,
                 integrator, control_period: float, substeps: int, squeeze_desired, max_deformation: float,
                 max_energy: float | None = None, torque_limits: bool = False, name: str = "scenario",
                 enabled: bool = True, step: float | None = None):
        self.plant = plant
        self.trajectory = trajectory
        self.grasps = np.asarray(grasps, dtype=float)
        self.ld = load_distribution
        self.compliance = compliance
        self.leader = leader
        self.followers = dict(followers)
        self.sensors = sensors
        self.integrator = integrator
        self.T = float(control_period)
        self.substeps = int(substeps)
        self.h = self.T / self.substeps
        self._steps = (self.h,) * self.substeps
        if step is not None:
            self.set_step(step)
        self.squeeze_desired = np.asarray(squeeze_desired, dtype=float)
        self.max_deformation = float(max_deformation)
        self.max_energy = max_energy
        self.torque_limits = bool(torque_limits)
        self.name = name
        self.enabled = bool(enabled)
        self.space = plant.space
        self.npos = 3 if self.space == "spatial" else 2
        el = plant.elastic
        self.object_mass = float(el.node_params[0, 0])
        self.object_inertia = el.node_params[0, 1:].copy()
        self.gravity = el.gravity.copy()
        self.tau_max = np.concatenate([np.asarray(a.tau_max, dtype=float) for a in plant.arms])
        #: The QP plans torques within ``TORQUE_HEADROOM`` of each limit, leaving the rest for
        #: the feedback terms; the applied torques are saturated at the limit (actuators).
        self._qp_tau_max = [TORQUE_HEADROOM * np.asarray(a.tau_max, dtype=float) for a in plant.arms]
        self._x_ref = None
        self._modes_cache: dict[int, tuple] = {}
        if self.space == "spatial":  # a nominal path through the Euler singularity is bad input
            check_nominal_path(trajectory, self.grasps)
        Yr = el.Y_ref
        self._rho = np.array([self._to_object_frame(Yr[0], Yr[i + 1, :self.npos] - Yr[0, :self.npos])
                              for i in range(plant.arm_count)])

    # ------------------------------------------------------------------ helpers
    def _to_object_frame(self, Y0, d):
        if self.space == "spatial":
            return rotation_zyx(Y0[3:6]).T @ d
        c, s = math.cos(Y0[2]), math.sin(Y0[2])
        return np.array([c * d[0] + s * d[1], -s * d[0] + c * d[1]])

    def _deformation(self, Y) -> tuple[float, int]:
        """Largest displacement [m] of a contact node from its rigid place on the object, and which."""
        worst, which = 0.0, 0
        for i in range(self.plant.arm_count):
            d = self._to_object_frame(Y[0], Y[i + 1, :self.npos] - Y[0, :self.npos]) - self._rho[i]
            v = float(np.sqrt(d @ d))
            if not v <= worst:  # also catches nan
                worst, which = v, i
        return worst, which

    def set_step(self, h: float, uniform: bool = False) -> None:
        """Integrate the plant with a free step ``h`` [s], ``0 < h <= T``.

        Each control period is ``n = floor(T / h)`` steps of ``h`` and, when ``T - n h`` is more
        than ``1e-9 T``, one remainder step ``T - n h < h``; the controller instants stay exactly
        ``k T``. For a Runge-Kutta scheme the one-step maps ``R(h A)`` of different steps commute
        (functions of the same ``A``), so the shorter remainder step cannot destabilize a stable
        ``h``; for symplectic Euler they do not, and a remainder step lowers its stability limit
        (to 0.8 of the uniform-step limit on an undamped scene). With ``uniform=True`` the period
        is instead split into ``n = ceil(T / h)`` equal steps ``T / n <= h`` (the largest step not
        above ``h`` that divides ``T``). ``h`` and ``substeps`` are updated to the steps taken.
        """
        h = float(h)
        if not (h > 0.0 and math.isfinite(h)) or h > self.T * (1.0 + 1e-12):
            raise ValueError(f"step = {h!r} is invalid: expected 0 < step <= control period {self.T:g} s")
        if uniform:
            n = max(1, int(math.ceil(self.T / h * (1.0 - 1e-12))))
            self.h, self.substeps = self.T / n, n
            self._steps = (self.h,) * n
            return
        n = max(1, int(math.floor(self.T / h * (1.0 + 1e-12))))
        rest = self.T - n * h
        self.h = h
        self.substeps = n
        self._steps = (h,) * n + ((rest,) if rest > 1e-9 * self.T else ())

    def modes(self, x=None):
        """:class:`~coopctrl.analysis.modes.ModalAnalysis` of the plant about ``x`` (default: the state
        the last run started from; ``ValueError`` before any run); cached per state."""
        from coopctrl.analysis.modes import linear_modes

        if x is None:
            if self._x_ref is None:
                raise ValueError("no state to linearize about: pass x, or run the loop first")
            x = self._x_ref
        x = np.asarray(x, dtype=float)
        key = hash(x.tobytes())
        hit = self._modes_cache.get(key)
        if hit is None or not np.array_equal(hit[0], x):
            hit = (x.copy(), linear_modes(self.plant, x))
            self._modes_cache[key] = hit
        return hit[1]

    def omega_max(self, x=None) -> float:
        """Highest elastic mode [rad/s] of the plant linearized at ``x`` (see :meth:`modes`):
        ``sqrt`` of the largest generalized eigenvalue of the stiffness against ``Gamma``.

        The arms' inertia is included, so this is the frequency the integrator actually meets.
        """
        return self.modes(x).omega_max

    def predicted_max_step(self, x=None) -> float:
        """The chosen integrator's largest stable step [s] on the linearization at ``x``, with the
        damping and coupling of every mode (:meth:`Integrator.max_stable_step`)."""
        return self.modes(x).predicted_max_step(self.integrator)

    def suggested_step(self, x=None) -> float | None:
        """A step [s] the chosen integrator should survive: half its predicted limit at ``x``, at most
        ``T``; ``None`` when no step helps (explicit Euler on an undamped mode: limit 0)."""
        limit = self.predicted_max_step(x)
        if limit == 0.0:
            return None
        return 0.5 * min(limit, 2.0 * self.T)

    def _step_advice(self, x_fail=None) -> tuple[float | None, str]:
        """``(suggested step, advice)`` after a failure at step ``h``: when ``h`` exceeds the predicted
        limit at the start state or at a state ``x_fail`` shortly before the failure, half the smaller
        limit (which is below ``h``); otherwise no step and a sentence saying the step is not the likely
        cause."""
        limits = [self.predicted_max_step()]
        if x_fail is not None and np.all(np.isfinite(x_fail)):
            try:
                limits.append(self.predicted_max_step(x_fail))
            except (PlantError, np.linalg.LinAlgError, ValueError):
                pass
        limit = min(limits)
        name = getattr(self.integrator, "name", type(self.integrator).__name__)
        if limit == 0.0:
            return None, (f"{name} is unstable at every step on an undamped mode of this plant: use "
                          "symplectic_euler, rk4, or implicit_euler for stiff grasps")
        if self.h > limit:
            return 0.5 * limit, ""
        return None, (f"the step h = {self.h:.3g} s is within {name}'s predicted stability limit {limit:.3g} s, "
                      "so the step is not the likely cause")

    def numerically_stable_step(self) -> bool:
        """True if the integration step is within the chosen integrator's predicted limit."""
        return self.h <= self.predicted_max_step()

    def diagnose(self, x) -> str:
        """Why a run at state ``x`` (the loaded start) cannot stay bounded, if the physics says so.

        Checks the object's stiffness with the contact nodes held (:meth:`ElasticSystem.node_stiffness`):
        a negative eigenvalue is a static instability of the grasp, whatever the step.
        """
        Y = self.plant.node_poses(x)
        K0 = self.plant.elastic.node_stiffness(Y, 0)
        npos = self.npos
        ev, vec = np.linalg.eigh(K0[:npos, :npos])
        if ev[0] < 0:
            d = vec[:, 0] * np.sign(vec[np.argmax(np.abs(vec[:, 0])), 0])
            axes = "xyz" if npos == 3 else "xz"
            direction = ", ".join(f"{c}: {v:+.2f}" for c, v in zip(axes, d))
            return (f"the grasp is statically unstable: the object's translational stiffness has a negative "
                    f"eigenvalue {ev[0]:.4g} N/m along ({direction}); central springs carry lateral load only "
                    "through tension and squeeze makes their lateral stiffness negative, so the object buckles out "
                    "of the grasp line (MODEL.md s.3). Use element = \"offset\" (shear stiffness) or less squeeze")
        return ""

    def _torque_model(self, terms, ddYn):
        """QP torque-limit rows: ``tau_i = Jg_i^T F_i + bias_i`` with the nominal node accelerations."""
        jac, bias = [], []
        for i, arm in enumerate(self.plant.arms):
            k = i + 1
            n = arm.dof
            if isinstance(arm, ContactPoint):
                jac.append(np.eye(self.plant.p))
                bias.append(terms.W[k] @ ddYn[k] + terms.w_free[k])
                continue
            J = terms.J[i, :, :n]
            if self.space == "spatial":
                Ai = terms.Y[k, 3:6]
                Jg = J.copy()
                Jg[3:] = rotation_zyx(Ai) @ body_rate_map(Ai) @ J[3:]
            else:
                Jg = J
            try:
                qdd = task_acceleration(terms, i, n, ddYn[k] - terms.Jdq[i])  # J^-1, or J^# if redundant
            except np.linalg.LinAlgError:
                qdd = np.zeros(n)
            jac.append(Jg)
            bias.append(terms.H[i, :n, :n] @ qdd + terms.h[i, :n] + J.T @ (terms.W[k] @ ddYn[k] + terms.w_free[k]))
        return jac, bias

    def _normals(self, terms):
        """Inward contact normals: each node's approach axis (its frame's x axis)."""
        Y = terms.Y
        out = np.empty((self.plant.arm_count, self.npos))
        for i in range(self.plant.arm_count):
            if self.space == "spatial":
                out[i] = rotation_zyx(Y[i + 1, 3:6])[:, 0]
            else:
                out[i] = (math.cos(Y[i + 1, 2]), math.sin(Y[i + 1, 2]))
        return out

    def loaded_state(self, x_unloaded) -> np.ndarray:
        """The loaded state at rest at t = 0, as the controllers plan it.

        The object is on its nominal pose; each contact node is at the pose that makes its
        interconnection carry the QP split of t = 0 (with the desired squeeze); each arm reaches
        its node by inverse kinematics (seeded with the unloaded configuration).
        """
        plant = self.plant
        p, npos, m = plant.p, self.npos, plant.arm_count
        Y0N, dY0N, ddY0N = self.trajectory.evaluate(0.0)
        Yn = nominal_node_motion(Y0N, dY0N, ddY0N, self.grasps, self.space)[0]
        w_N = required_object_wrench(self.space, self.object_mass, self.object_inertia, self.gravity, Y0N, dY0N, ddY0N)
        from coopctrl.load_distribution import LoadDistribution

        ld = LoadDistribution(self.ld.config, self.space, m)
        terms = plant.control_terms(x_unloaded)
        kwargs = {}
        if self.ld.config.min_grip is not None or self.ld.config.friction_coefficient is not None:
            kwargs["normals"] = self._normals(terms)
        if self.torque_limits:
            kwargs["jacobians"], kwargs["biases"] = self._torque_model(terms, np.zeros((m + 1, p)))
            kwargs["tau_max"] = self._qp_tau_max
        if self.ld.config.split == "elastic":
            kwargs["K"] = self.compliance.stiffness_world(Y0N)
        F = ld.solve(Yn[1:, :npos], Y0N[:npos], w_N, **kwargs).F
        x = np.array(x_unloaded, dtype=float)
        nz = plant.nz
        x[nz:] = 0.0
        x[nz - p:nz] = Y0N
        for i, arm in enumerate(plant.arms):
            Yi = self.compliance.deformation(i, F[i], Y0N, Yn[i + 1])
            sl = plant.q_slice(i)
            x[sl] = arm.inverse_kinematics(Yi, x_unloaded[sl]) if not isinstance(arm, ContactPoint) else Yi
        return x

    # ------------------------------------------------------------------ the loop
    def run(self, x0, duration: float, progress: bool = False, integrals=None):
        """Simulate ``duration`` [s] from ``x0``; returns its :class:`~coopctrl.loop.record.LoopRecord`.

        Every run starts from a fresh loop state (:class:`~coopctrl.loop.state.LoopState`): the
        sensor noise streams from their seeds, no QP warm start and no last split, the followers'
        force-error integrals zero or, with ``integrals`` (arm index -> (p,) [N s, N m s]), those
        values (an operating point). The same call twice gives bit-identical records.
        """
        N = int(round(duration / self.T)) + 1
        check_record_fits(N, sum(v[:1].size for v in self.empty_record(1).values() if isinstance(v, np.ndarray)),
                          duration, self.T)  # before allocating: refuse, with the size, what cannot fit
        rec = self.empty_record(N)
        self._initial_integrals = {} if integrals is None else {int(i): np.asarray(v, dtype=float).copy()
                                                               for i, v in integrals.items()}
        return self._run(rec, x0, N, progress)

    def empty_record(self, N: int = 0):
        """The :class:`~coopctrl.loop.record.LoopRecord` of ``N`` ticks (NaN-filled; a run truncates it)."""
        from coopctrl.loop.record import LoopRecord

        plant = self.plant
        return LoopRecord.empty(N, plant.state_size, plant.input_size, plant.arm_count, plant.p, self.npos)

    def _fresh_load_distribution(self):
        """A load distribution with this loop's settings and no history (no warm start, no last split)."""
        from coopctrl.load_distribution import LoadDistribution

        return LoadDistribution(self.ld.config, self.space, self.plant.arm_count)

    def _run(self, rec, x0, N, progress):
        """Run ``N`` ticks from ``x0`` into ``rec``: the one tick of :mod:`coopctrl.loop.kernel`, driven by
        :func:`coopctrl.loop.compiled.run_compiled` for every configuration. The reference path
        (``load_distribution.solver`` other than ``"compiled"``) runs the same kernel, which hands each QP
        it assembles to the chosen backend; an integrator the kernel lacks steps the plant in Python
        between kernel calls; passive runs, ``max_energy``, the elastic split and the tuning probes are
        kernel inputs."""
        from coopctrl.loop.compiled import run_compiled

        return run_compiled(self, rec, x0, N, progress)

    def _stop_reason(self, exc, k: int, k_done: int, rec, x, x_good, t_good: float, x0, events,
                     saturation: dict) -> tuple[str, str]:
        """``(status, reason)`` of a run stopped at tick ``k`` by ``exc`` (after ``k_done`` recorded ticks),
        with its event appended to ``events``: the diagnosis, shared by the Python and compiled ticks.
        ``saturation``: ``saturated_ticks``, ``saturated_joint_ticks``, ``saturation_first_time_s`` and
        ``saturated_last_tick`` so far (the diagnosis' evidence)."""
        spatial = self.space == "spatial"
        near = margin_cos(2.0 * EULER_PITCH_MARGIN_DEG)  # a failure this close is blamed on the singularity
        if isinstance(exc, _NearSingularity):
            status, reason = "diverged", self._singularity_reason(exc.hit)
            events.append((exc.hit.time, "euler_singularity", reason))
        elif isinstance(exc, (DivergenceError, PlantError)):
            status = "diverged"
            hit = self._nearest_singularity(x, k * self.T, x_good, t_good) if spatial else None
            if isinstance(exc, EulerSingularityError) or (hit is not None and hit.cos_theta < near):
                if isinstance(exc, EulerSingularityError) and (hit is None or hit.cos_theta >= near):
                    hit = _hit_from_plant_error(exc, k * self.T)  # reached inside a control period
                reason = self._singularity_reason(hit, f"{exc}" if isinstance(exc, DivergenceError) else "")
                events.append((hit.time, "euler_singularity", reason))
            else:
                # the advice is taken a few ticks before the failure: the last good state may already be wild
                back = max(0, k_done - 1 - DIAGNOSIS_TICKS_BACK)
                x_back = rec["x"][back] if k_done else np.asarray(x0, dtype=float)
                t_back = float(rec["t"][back]) if k_done else 0.0
                chart = self._chart_stiffening(x_back, t_back, np.asarray(x0, dtype=float)) if spatial else ""
                evidence = dict(saturation, events=events)
                reason = self._divergence_reason(exc, k * self.T, x_back, np.asarray(x0, dtype=float), chart,
                                                 evidence=evidence, k_done=k_done, t_back=t_back)
                events.append((getattr(exc, "time", k * self.T), "euler_singularity" if chart else "diverged", reason))
        else:  # InfeasibleLoad
            from coopctrl.analysis.diagnosis import held_split_cause

            held = held_split_cause(events)
            status, reason = "qp_failed", f"at t = {k * self.T:.6g} s: {exc}" + (f"; cause: {held}" if held else "")
            events.append((k * self.T, "qp_failed", str(exc)))
        return status, reason

    def _chart_stiffening(self, x_back, t_back: float, x0) -> str:
        """Why the step failed, if it is the Euler-angle chart; else ``""``.

        Blamed on the chart when, at the state ``x_back`` a few ticks before the failure (or else at the
        start state ``x0``), the step is beyond the integrator's predicted limit and the mode that sets
        that limit lives mostly (share > 1/2,
        :func:`~coopctrl.analysis.euler_singularity.chart_mode_share`) on the Euler angles of nodes
        pitched beyond 45 deg: rotational stiffness and damping written in Euler-angle coordinates act
        on the inertia ``L^T I L``, which loses rank like ``cos^2(theta)`` (MODEL.md s.2), so such a
        mode stiffens like ``1 / cos^2(theta)`` on the way to the singularity.
        """
        from coopctrl.analysis.euler_singularity import chart_mode_share

        for x, t in ((x_back, t_back), (x0, 0.0)):
            try:
                modes = self.modes(x)
                limit = modes.predicted_max_step(self.integrator)
                k = modes.limiting_mode(self.integrator)
                if k is None or not self.h > limit:
                    continue
                share, hit = chart_mode_share(self.plant, x, modes.eigenvectors[:, k])
            except (PlantError, np.linalg.LinAlgError, ValueError):
                continue
            if share > 0.5:
                break
        else:
            return ""
        hit = SingularityHit(hit.node, hit.theta, hit.cos_theta, t)
        name = getattr(self.integrator, "name", type(self.integrator).__name__)
        return (f"approaching the Euler-angle singularity: {hit.describe()}; the mode that limits {name} there "
                f"({abs(modes.eigenvalues[k]):.4g} rad/s, {100 * share:.0f} % on the Euler angles of pitched nodes) "
                "is stiffened by the Euler-angle chart (rotational stiffness and damping in Euler-angle coordinates act "
                "on an inertia L^T I L that vanishes like cos^2(theta)); a smaller step only helps until the pitch "
                f"grows further; {fix_hint()}")

    def _divergence_reason(self, exc, t_fail: float, x_back, x0, chart: str = "", evidence: dict | None = None,
                           k_done: int = 0, t_back: float = 0.0) -> str:
        """One line: what left its bounds and when, then its causes checked against the run's ``evidence``
        (:func:`coopctrl.analysis.diagnosis.diagnose_failure`: static instability, an unreachable pose,
        torque saturation, a held QP split, the step), and step advice only when the step is the cause
        (its closed-loop predicted limit at the start and at ``x_back``, a few ticks before the failure)."""
        from coopctrl.analysis.diagnosis import Diagnosis, diagnose_failure

        try:
            diag = diagnose_failure(self, evidence or {}, k_done, t_fail, x_back, t_back, x0)
        except Exception:  # noqa: BLE001 - the diagnosis must never replace the failure it explains
            diag = Diagnosis((), self.h > self.predicted_max_step(), math.nan)
        if diag.step_is_cause:
            step, advice = self._step_advice(x_back)
            if step is None and advice.startswith("the step h"):  # within the open-loop limit: half the closed-loop one
                step, advice = 0.5 * min(diag.closed_loop_limit_s, 2.0 * self.T), ""
        else:
            limit = diag.closed_loop_limit_s
            name = getattr(self.integrator, "name", type(self.integrator).__name__)
            shown = (f"the closed loop's stable range (its linearization has no limit below the control period "
                     f"{self.T:g} s)" if limit == math.inf else
                     f"{name}'s predicted closed-loop stability limit {limit:.3g} s" if not math.isnan(limit) else
                     f"{name}'s predicted stability limit {self.predicted_max_step():.3g} s")
            step, advice = None, f"the step h = {self.h:.3g} s is within {shown}, so the step is not the likely cause"
        if isinstance(exc, DivergenceError):
            if type(exc) is DivergenceError:
                reason = str(DivergenceError(exc.time, exc.quantity, exc.value, step))
            else:  # an integrator's own failure (Newton): its message already says what to change
                reason = str(exc) + (f"; the predicted stability limit suggests at most {step:.3g} s" if step else "")
                advice = ""
        else:
            reason = f"diverged at t = {t_fail:.6g} s: {exc}" + (f"; try a step of at most {step:.3g} s" if step else "")
        if chart:
            return f"{reason}; {chart}"
        if advice:
            reason = f"{reason}; {advice}"
        quantity = getattr(exc, "quantity", "")
        if getattr(exc, "time", None) == 0.0 and quantity.startswith("deformation"):
            reason = (f"{reason}: the start state already deforms the grasp beyond simulation.max_deformation = "
                      f"{self.max_deformation:g} m (a static deflection |F| / k: the interconnections are too soft for "
                      "the load); raise the stiffness, lower the load or raise max_deformation")
        causes = list(diag.causes)
        if causes and causes[0] == self.diagnose(x0):  # static instability: the physics' own sentence
            reason = f"{reason}: {causes.pop(0)}"
        if causes:
            reason = f"{reason}; cause: " + "; ".join(causes)
        return reason

    def _nearest_singularity(self, x, t: float, x_good, t_good: float) -> SingularityHit:
        """The node closest to pitch +-90 deg in the failing state ``x`` (if finite) or the last good one."""
        hits = []
        for state, when in ((x, t), (x_good, t_good)):
            if np.all(np.isfinite(state)):
                try:
                    hits.append(closest_to_singularity(self.plant.node_poses(state).reshape(-1, self.plant.p), when))
                except PlantError:
                    pass
        return min(hits, key=lambda h: h.cos_theta) if hits else SingularityHit(0, 0.0, 1.0, t_good)

    def _singularity_reason(self, hit, detail: str = "") -> str:
        """One line for a run stopped at the Euler-angle singularity."""
        after = f" (the integration then failed: {detail})" if detail else ""
        return (f"Euler-angle singularity at t = {hit.time:.6g} s: {hit.describe(with_time=False)}{after}; a smaller step does not "
                f"help: {fix_hint()}")

    # ------------------------------------------------------------------ post-processing
    def squeeze_of(self, F, r_contacts, r_object) -> np.ndarray:
        """Virtual-linkage squeeze [N] of the internal part of contact wrenches ``F`` (m, p).

        The internal part is ``F - G^+ G F`` (the Moore-Penrose split of the same resultant),
        decomposed on the virtual-linkage basis by least squares.
        """
        G = grasp_matrix(r_contacts, r_object, self.space)
        f = F.reshape(-1)
        f_int = f - np.linalg.pinv(G) @ (G @ f)
        E = internal_force_basis(r_contacts, self.space)
        return np.linalg.lstsq(E, f_int, rcond=None)[0]


class _NearSingularity(Exception):
    """Internal: a node of the running state entered the band around pitch +-90 deg."""

    def __init__(self, hit):
        super().__init__(hit.describe())
        self.hit = hit


def _hit_from_plant_error(exc, t: float) -> SingularityHit:
    """A :class:`SingularityHit` from the plant's :class:`EulerSingularityError` (or an unknown place)."""
    theta = float(getattr(exc, "theta", math.nan))
    node = 0
    where = str(getattr(exc, "where", ""))
    if where.startswith("contact node "):
        digits = where[len("contact node "):].split()[0]
        node = int(digits) if digits.isdigit() else 0
    c = abs(math.cos(theta)) if math.isfinite(theta) else 0.0
    return SingularityHit(node, theta if math.isfinite(theta) else 0.5 * math.pi, c, t)
