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
its causes checked against the run's evidence (:mod:`coopctrl.loop.diagnosis`: static
instability, an unreachable pose, torque saturation, a held QP split, and the step, with a suggested
step only when the step is beyond the closed loop's predicted limit); it never runs on silently. A
spatial node whose pitch comes within
:data:`~coopctrl.loop.euler_band.EULER_PITCH_MARGIN_DEG` of +-90 deg stops the run as
an Euler-angle singularity (and a nominal path that does is refused when the loop is built).

The loop's other concepts have files of their own in :mod:`coopctrl.loop`: the failure diagnosis
(:mod:`~coopctrl.loop.diagnosis`), the loaded start (:mod:`~coopctrl.loop.loaded_start`), the Euler-angle
band (:mod:`~coopctrl.loop.euler_band`) and the QP's contact inputs (:mod:`~coopctrl.loop.qp_inputs`, defined in
the compiled core's coopctrl/core/qp_contact_model.h);
the methods below that name them delegate. The loop imports nothing of ``coopctrl.analysis``.
"""

from __future__ import annotations

import math
from typing import Mapping

import numpy as np

import coopctrl.arguments as arguments
from coopctrl.load_distribution import grasp_matrix
from coopctrl.loop import charts as loop_charts
from coopctrl.loop import diagnosis, loaded_start
from coopctrl.loop.diagnosis import DIAGNOSIS_TICKS_BACK
from coopctrl.loop.euler_band import check_nominal_path
from coopctrl.loop.parts import LoopControllers, LoopGuards, LoopTiming
from coopctrl.loop.qp_inputs import TORQUE_HEADROOM, qp_torque_limits
from coopctrl.record_memory import check_record_fits
from plants.frames import rotation_zyx

__all__ = ["ClosedLoop", "DIAGNOSIS_TICKS_BACK", "TORQUE_HEADROOM"]


class ClosedLoop:
    """A fixed-step closed loop over a cooperative plant.

    Args:
        plant: The cooperative plant (simulated, and also the controllers' model).
        trajectory: Object trajectory with ``evaluate(t) -> (Y, dY, ddY)``.
        grasps: (m, p) grasp poses in the object frame, as the controllers know them.
        load_distribution: :class:`~coopctrl.load_distribution.LoadDistribution`: the split and, from its
            configuration, the desired squeeze per pair [N] and whether the QP has torque rows.
        controllers: :class:`~coopctrl.loop.parts.LoopControllers`: the leader, the followers, the grasp
            compliance, the nodes' laws, and whether the controllers run.
        sensors: :class:`~coopctrl.sensors.SensorSuite`.
        timing: :class:`~coopctrl.loop.parts.LoopTiming`: the integrator, the control period ``T`` [s] and the
            plant's steps in it.
        guards: :class:`~coopctrl.loop.parts.LoopGuards`: the deformation [m] and energy [J] bounds.
        name: The loop's name (the scenario's).
        rotations: ``"book"``: the loop runs in the book's world angles; ``"charts"`` (spatial): in a world chart
            re-centred on the object (:mod:`coopctrl.loop.charts`).
        failure_causes: Optional ``(loop, evidence, k_done, t_fail, x_back, t_back, x0) -> Diagnosis``:
            the causes of a divergence checked against the closed loop's predicted step limit (see
            :mod:`coopctrl.loop.diagnosis`).
    """

    def __init__(self, plant, trajectory, grasps, load_distribution, controllers: LoopControllers, sensors,
                 timing: LoopTiming, guards: LoopGuards, *, name: str = "scenario", rotations: str = "book",
                 failure_causes=None):
        for arg, value, cls in (("controllers", controllers, LoopControllers), ("timing", timing, LoopTiming),
                                ("guards", guards, LoopGuards)):
            arguments.instance(arg, value, cls, f"a coopctrl.loop.parts.{cls.__name__}")
        self.plant = plant
        self.trajectory = trajectory
        self.grasps = np.asarray(grasps, dtype=float)
        self.ld = load_distribution
        self.compliance = controllers.compliance
        self.leader = controllers.leader
        self.followers = dict(controllers.followers)
        self.leader_law = controllers.leader_law
        self.follower_law = controllers.follower_law
        self.enabled = controllers.enabled
        self.sensors = sensors
        self.integrator = timing.integrator
        self.T = timing.control_period
        self.substeps = timing.substeps
        self.h = self.T / self.substeps
        self._steps = (self.h,) * self.substeps
        if timing.step is not None:
            self.set_step(timing.step)
        config = load_distribution.config
        #: (n_pairs,) the desired virtual-linkage squeeze [N] (the load distribution's)
        self.squeeze_desired = np.asarray(config.squeeze_per_pair(plant.arm_count), dtype=float)
        self.torque_limits = bool(config.torque_limits)
        self.max_deformation = guards.max_deformation
        self.max_energy = guards.max_energy
        self.name = name
        if rotations not in ("book", "charts") or (rotations == "charts" and plant.space != "spatial"):
            raise ValueError(f"rotations = {rotations!r} is invalid: expected 'book' or, for a spatial plant, 'charts'")
        #: ``"book"``: the loop runs in the book's world angles; ``"charts"``: in a world chart re-centred on the
        #: object (:mod:`coopctrl.loop.charts`).
        self.rotations = rotations
        if getattr(plant, "charted", False):
            raise ValueError("plant is in rotation charts (CooperativePlant.with_charts): the loop's controllers "
                             "work on the book's world angles; pass the plant in them and rotations = 'charts' "
                             "for a scene that turns through pitch 90 deg")
        self.failure_causes = failure_causes
        self.space = plant.space
        self.npos = 3 if self.space == "spatial" else 2
        el = plant.elastic
        self.object_mass = float(el.node_params[0, 0])
        self.object_inertia = el.node_params[0, 1:].copy()
        self.gravity = el.gravity.copy()
        self.tau_max = np.concatenate([np.asarray(a.tau_max, dtype=float) for a in plant.arms])
        #: Per arm, the joint torque limits the QP plans within [N m]: ``TORQUE_HEADROOM`` of each limit, leaving the
        #: rest for the feedback terms; the applied torques are saturated at the limit (actuators).
        self.qp_torque_limits = qp_torque_limits(plant)
        self._modes_cache: dict[int, tuple] = {}
        if self.space == "spatial" and rotations == "book":  # a nominal path through the Euler singularity is bad input
            check_nominal_path(trajectory, self.grasps)
        elif self.space == "spatial":  # in charts: a contact node's angles in the object's chart
            loop_charts.check_nominal_path_in_charts(trajectory, self.grasps)
        Yr = el.Y_ref
        #: (m, npos) the contact points in the object frame at the unloaded pose [m]
        self.contact_points = np.array([self._to_object_frame(Yr[0], Yr[i + 1, :self.npos] - Yr[0, :self.npos])
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
            d = self._to_object_frame(Y[0], Y[i + 1, :self.npos] - Y[0, :self.npos]) - self.contact_points[i]
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
        h = arguments.number("step", h, positive=True, unit="s")
        uniform = arguments.flag("uniform", uniform)
        if h > self.T * (1.0 + 1e-12):
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

    @property
    def steps(self) -> tuple[float, ...]:
        """The plant steps of one control period [s] (they sum to ``T``; see :meth:`set_step`)."""
        return self._steps

    def modes(self, x=None):
        """:class:`~coopctrl.integrators.modes.ModalAnalysis` of the plant about ``x``, a state of the plant
        (a run keeps nothing on the loop, so there is no default: ``None`` raises ``ValueError``); cached
        per state."""
        from coopctrl.integrators.modes import linear_modes

        if x is None:
            raise ValueError("x = None: no state to linearize about; pass x, a state of the plant "
                             "(e.g. coopctrl.scenario.build.initial_state(scenario))")
        x = self._state("x", x)
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

    def numerically_stable_step(self, x) -> bool:
        """True if the integration step is within the chosen integrator's predicted limit at ``x``."""
        return self.h <= self.predicted_max_step(x)

    def diagnose(self, x) -> str:
        """Why a run at state ``x`` (the loaded start) cannot stay bounded, if the physics says so
        (:func:`coopctrl.loop.diagnosis.static_instability`); else ``""``."""
        return diagnosis.static_instability(self, self._state("x", x))

    def loaded_state(self, x_unloaded) -> np.ndarray:
        """The loaded state at rest at t = 0, as the controllers plan it, from this loop's parts
        (:func:`coopctrl.loop.loaded_start.loaded_state`)."""
        return loaded_start.loaded_state(self.plant, self.trajectory, self.grasps, self.ld.config, self.compliance,
                                         self.torque_limits, self._state("x_unloaded", x_unloaded))

    # ------------------------------------------------------------------ the loop
    def run(self, x0, duration: float, progress: bool = False, integrals=None):
        """Simulate ``duration`` [s] from ``x0``; returns its :class:`~coopctrl.loop.record.LoopRecord`.

        ``x0`` is a plant state or a :class:`~coopctrl.loop.state.LoopState`. From a plant state, the run
        starts from a fresh loop state: the sensor noise streams from their seeds, no QP warm start and no
        last split, the followers' force-error integrals zero or, with ``integrals`` (arm index -> (p,)
        [N s, N m s]), those values (an operating point); it records ``round(duration / T) + 1`` ticks, at
        ``t = 0 .. duration``. The same call twice gives bit-identical records.

        From a run's ``record.final_state``, the run continues it: ``round(duration / T)`` more ticks, at
        ``t = t_end + T .. t_end + duration``, with everything the loop carries from tick to tick (the state,
        held torques, integrals, QP warm start, the integrator's step-to-step state, the sensor noise
        streams, the rotation chart) taken from where it ended. The two records, one after the other, are
        those of one run of the summed duration, bit for bit; on the reference path
        (``load_distribution.solver`` other than ``"compiled"``) to that solver's tolerance, as its backend
        starts cold, and a tuning probe's measurement delay starts afresh. The state given is left unchanged: it can be continued again.

        Raises:
            TypeError, ValueError: ``x0`` not ``plant.state_size`` finite numbers nor a loop state of this loop
                (or the final state of a run that stopped early), ``duration`` not a finite number >= 0 [s],
                ``progress`` not a bool, ``integrals`` not a mapping of follower index to ``p`` finite numbers
                (or given with a loop state, which has its own); the message names the argument; checked once,
                before the run.
        """
        from coopctrl.loop.state import LoopState

        start = None
        if isinstance(x0, LoopState):
            start = self._continuable("x0", x0)
            if integrals is not None:
                raise arguments.invalid("integrals", integrals, "None when x0 is a LoopState (it carries the "
                                        "followers' integrals)")
            x0 = start.x
        else:
            x0 = self._state("x0", x0)
        duration = arguments.number("duration", duration, minimum=0.0, unit="s")
        progress = arguments.flag("progress", progress)
        integrals = self._integrals(integrals)
        N = int(round(duration / self.T)) + (1 if start is None else 0)
        check_record_fits(N, sum(v[:1].size for v in self.empty_record(1).values() if isinstance(v, np.ndarray)),
                          duration, self.T)  # before allocating: refuse, with the size, what cannot fit
        rec = self.empty_record(N)
        start_integrals = {} if integrals is None else {int(i): np.asarray(v, dtype=float).copy()
                                                        for i, v in integrals.items()}
        return self._run(rec, x0, N, progress, start_integrals, start)

    def _continuable(self, name: str, state):
        """``state`` (a :class:`~coopctrl.loop.state.LoopState`) checked as one this loop can continue from."""
        import coopctrl.integrators.compiled as I

        plant = self.plant
        allowed = (f"a plant state of size {plant.state_size}, or the final_state of a run of this loop "
                   "(record.final_state)")
        if not state.resumable:
            raise arguments.invalid(name, state, f"{allowed} that ended ok: this run stopped early and cannot be "
                                    "continued", ValueError)
        m, p = plant.arm_count, plant.p
        if (np.shape(state.x) != (plant.state_size,) or np.shape(state.tau) != (plant.input_size,)
                or np.shape(state.integrals) != (m, p)):
            raise arguments.invalid(name, state, f"{allowed}: its sizes are another loop's", ValueError)
        if state.chart is not None and self.rotations != "charts":
            raise arguments.invalid(name, state, f"{allowed}: it is the state of a run in rotation charts and this "
                                    "loop runs in the book's angles (scene.rotations)", ValueError)
        if state.plan is not None:
            try:
                fresh = I.make_plan(self.integrator, plant.state_size, self.T, 1)
            except TypeError:
                fresh = None
            if type(fresh) is not type(state.plan):
                raise arguments.invalid(name, state, f"{allowed}: it was run with another integrator than "
                                        f"{getattr(self.integrator, 'name', type(self.integrator).__name__)!r}",
                                        ValueError)
        return state

    def _state(self, name: str, x) -> np.ndarray:
        """``x`` checked as a state of the plant: ``plant.state_size`` finite numbers (a float copy)."""
        n, nz = self.plant.state_size, self.plant.nz
        return arguments.vector(name, x, n, f"a state of the plant, (z, dz/dt) of size {n} = 2 x {nz} "
                                "(coopctrl.scenario.build.initial_state(scenario) gives the scenario's)")

    def _integrals(self, integrals) -> dict | None:
        """``integrals`` checked: None, or follower arm index -> ``p`` finite numbers [N s, N m s]."""
        if integrals is None:
            return None
        allowed = f"None or a mapping of follower arm index ({sorted(self.followers)}) to {self.plant.p} numbers"
        if not isinstance(integrals, Mapping):
            raise arguments.invalid("integrals", integrals, allowed, TypeError)
        checked = {}
        for i, value in integrals.items():
            if isinstance(i, bool) or not isinstance(i, (int, np.integer)) or int(i) not in self.followers:
                raise arguments.invalid("integrals", integrals, f"{allowed} (the key {i!r} is no follower)")
            checked[int(i)] = arguments.vector(f"integrals[{int(i)}]", value, self.plant.p,
                                               "a follower's force-error integral [N s, N m s]")
        return checked

    def empty_record(self, N: int = 0):
        """The :class:`~coopctrl.loop.record.LoopRecord` of ``N`` ticks (NaN-filled; a run truncates it)."""
        from coopctrl.loop.record import LoopRecord

        plant = self.plant
        return LoopRecord.empty(N, plant.state_size, plant.input_size, plant.arm_count, plant.p, self.npos)

    def fresh_load_distribution(self):
        """A load distribution with this loop's settings and no history (no warm start, no last split)."""
        from coopctrl.load_distribution import LoadDistribution

        return LoadDistribution(self.ld.config, self.space, self.plant.arm_count)

    def _run(self, rec, x0, N, progress, integrals, start=None):
        """Run ``N`` ticks from ``x0`` into ``rec``: the one compiled tick (coopctrl/core/tick.h), driven by
        :func:`coopctrl.loop.run.run_compiled` for every configuration. The reference path
        (``load_distribution.solver`` other than ``"compiled"``) runs the same kernel, which hands each QP
        it assembles to the chosen backend; an integrator the kernel lacks steps the plant in Python
        between kernel calls; passive runs, ``max_energy``, the elastic split and the tuning probes are
        kernel inputs. ``integrals``: the followers' starting integrals (arm index -> (p,)); ``start``: the
        loop state to continue from (None: a fresh one)."""
        from coopctrl.loop.run import run_compiled

        return run_compiled(self, rec, x0, N, progress, integrals, start)

    def stop_reason(self, exc, k: int, k_done: int, rec, x, x_good, t_good: float, x0, events,
                     saturation: dict) -> tuple[str, str]:
        """:func:`coopctrl.loop.diagnosis.stop_reason` of this loop (the Python and compiled ticks call it): the
        loop's own reason, with the stop's raw facts recorded as ``rec["stop"]`` for a diagnosis after the run."""
        return diagnosis.stop_reason(self, exc, k, k_done, rec, x, x_good, t_good, x0, events, saturation)

    # ------------------------------------------------------------------ post-processing
    def squeeze_of(self, F, r_contacts, r_object) -> np.ndarray:
        """Virtual-linkage squeeze [N] of the internal part of contact wrenches ``F`` (m, p).

        The internal part is ``F - G^+ G F`` (the Moore-Penrose split of the same resultant), its
        pair tensions those of :func:`~coopctrl.load_distribution.grasp_matrix.virtual_linkage_squeeze`
        (nearest the desired squeeze where the pairs are dependent; NaN where ill-conditioned).
        """
        from coopctrl.load_distribution.grasp_matrix import virtual_linkage_squeeze

        G = grasp_matrix(r_contacts, r_object, self.space)
        f = np.asarray(F, dtype=float).reshape(-1)
        f_int = f - np.linalg.pinv(G) @ (G @ f)
        return virtual_linkage_squeeze(f_int, r_contacts, self.space, self.squeeze_desired)

