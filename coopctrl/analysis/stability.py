"""Stability limits of the integrators on a scenario: predicted from the linearizations of the
open-loop plant and of the closed loop, measured by bisection on the actual closed loop.

**Predicted, open loop.** :func:`~coopctrl.analysis.modes.linear_modes` about the state the run starts from
(``build.initial_state``: the loaded state at rest, or the unloaded one for ``start = "unloaded"``)
gives ``omega_max`` and the damping of the highest mode; each integrator's largest stable step is
:meth:`Integrator.max_stable_step` of the linearization ``A`` (every mode, with its damping; the
physically unstable modes skipped, since no step cures them).

**Predicted, closed loop.** The loop that runs is not the open-loop plant: the controllers act on
every mode at each control instant (computed torque cancels the plant's own forces there). Its
one-period map (controller, ZOH, the scheme's steps of ``h``) linearized about the start state and
at instants of a nominal run, and the largest ``h`` whose spectral radius stays within the loop's
own (:mod:`coopctrl.analysis.closed_loop_stability`), is the closed-loop prediction; ``inf`` when
``h = T`` is stable (no limit below the control period).

**Measured.** The scenario's own closed loop (controllers, sensors, QP: :func:`coopctrl.wiring.closed_loop`)
is run from the same state over a short horizon with a free plant step ``h``
(:meth:`ClosedLoop.set_step`), the controller still at its period ``T``. A trial step is *stable*
when the run ends with status ``"ok"`` and the elastic energy of the interconnections (every
spring, translational and torsional: ``Pi(Y)`` of docs/model.md s.3) stays within
``(1 + GROWTH_BOUND)^2`` of the largest one of a reference run over the same time (RK4 at a quarter
of its predicted limit, at most ``T``), i.e. the deformation amplitude within ``1 + GROWTH_BOUND``::

    max_t Pi(t)  <=  (1 + GROWTH_BOUND)^2  max_t Pi_ref(t)      [J]

Magnitudes are compared, not the difference from the reference: a stable but inaccurate step
drifts in phase on a lightly damped oscillation (a difference then reaches twice the amplitude)
without growing, whereas a numerically unstable mode grows geometrically, by ``|R| > 1`` per
step, and breaks the bound (or a divergence bound) within the horizon. The energy sees every mode,
also a torsion mode that moves no contact force (a translational measure missed an unstable roll
mode of the contact nodes). The horizon is at least
:data:`MIN_PERIODS` control periods and :data:`MIN_STEPS` steps at the predicted limit: just above
a limit the growth per step is ``1 + kappa delta`` (``delta`` the relative excess, ``kappa`` ~ 2
to 7 for RK4 and symplectic Euler), so 2 % above it a mode excited at 1e-6 of the force scale
needs ~ ln(5e5) / 0.04 ~ 330 steps to reach the bound. Far above a limit the growth can still be
slow when the limiting mode is damped (explicit Euler on a lightly damped mode grows by
``|1 + h lambda| ~ 1.02`` per step at several times its limit), and slower still in the closed loop,
whose controllers act on the mode at every control instant (on ``spatial_two_puma_carry`` explicit
Euler at ``h = T`` diverges only at 2.39 s). So a trial whose step either linearization predicts
unstable (the open-loop one-step matrix, ``rho(M(h)) > 1``, or the closed loop's period map,
``rho(Phi(h))`` beyond the loop's own) runs for the scenario's whole duration
(:func:`growth_horizon`): the measured limit is the largest step that survives the scenario's own
run, not a short window of it. A step so
small that a trial would take more than :data:`MAX_TRIAL_STEPS` plant steps is not tried.

Every trial (and the reference) starts from the same state with a seeded perturbation of
:data:`SEED_PERTURBATION` on each coordinate of ``z`` (1 nm or 1 nrad): a symmetric scene leaves
its out-of-plane modes *exactly* unexcited (their coordinates stay 0.0 in floating point), so an
unstable one would never show; the seed gives every mode a start 7 orders of magnitude above
round-off and far below anything the accuracy notices.

A trial step ``h`` that does not divide ``T`` is taken as ``floor(T / h)`` steps of ``h`` plus a
shorter remainder step for the Runge-Kutta schemes (whose one-step maps commute, so the remainder
cannot destabilize), and as ``T / ceil(T / h)`` uniform steps for symplectic Euler (whose maps do
not commute: a remainder step lowers its limit by ~20 %); see :meth:`ClosedLoop.set_step`. Its
measured limit is therefore a step ``T / n``, resolved to ``1 / n`` relative.

**Twin runs.** A trial of a controlled loop that survives is run a second time, from the start state
moved by :data:`TWIN_PERTURBATION` along the least stable mode that the step moves in the start's
linearized period map (:class:`~coopctrl.analysis.closed_loop_stability.ModeProbe`: the loop's own slow
modes, the same at any step, are left out; no twin when the step moves no mode; a seeded random
direction when there is no closed-loop linearization). Both runs take the same steps, so their difference is the
evolution of that perturbation in the actual nonlinear loop, free of the discretization error both
share; its modal amplitude ``|w^H delta s|`` (``w`` the left eigenvector) has no beating, and a rise
above its seeded value by more than :data:`MODE_GROWTH` (on window means, :meth:`ModeProbe.growth`)
makes the trial unstable even when the run survives: on ``fidelity_spatial_arms``
explicit Euler at 1.3 times its closed-loop limit grows that mode by 1.0006 per period, 0.6 /s, which a
2.5 s run turns into a factor 5 of a tiny seed, invisible to any bound on the elastic energy, while
seeded on purpose the held loop shows exactly that rate (0.64 /s measured). The measurement remains a
simulation: if the linearization were wrong, the seeded mode would not grow and the trial would pass.
Only a controlled loop gets twin runs: it holds its reference, so at a stable step a perturbation
decays; a passive scene's free-floating and undamped modes let two nearby runs drift apart linearly in
time at any step (its trials keep the energy bound alone).

The bisection works on ``log h`` to a relative resolution (:data:`RESOLUTION`, 2 %). The loop
cannot take a step longer than ``T``: when ``h = T`` is stable the result is reported as
``measured = T`` with ``limited_by_control_period = True`` (a lower bound); the implicit schemes
(implicit midpoint, implicit Euler), unconditionally stable, are only tried at ``T``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from coopctrl.analysis.modes import ModalAnalysis, damping_ratio_of, linear_modes
from coopctrl.compact_repr import compact_repr
from coopctrl.integrators import INTEGRATORS, get_integrator

#: Relative bisection resolution on the measured limit [-].
RESOLUTION = 0.02
#: Allowed growth of the largest contact force over the reference run's [-].
GROWTH_BOUND = 0.5
#: Fewest control periods [-] and fewest plant steps at the predicted limit [-] of a trial run.
MIN_PERIODS = 50
MIN_STEPS = 400
#: Most plant steps in one trial [-] (bounds the cost of the search below a tiny predicted limit).
MAX_TRIAL_STEPS = 200_000
#: Size of the seeded perturbation of the generalized coordinates ``z`` of the start state [m or rad].
SEED_PERTURBATION = 1e-9
#: Size of the perturbation [m or rad] of each trial's twin run (largest position component; module docstring).
TWIN_PERTURBATION = 1e-7
#: Growth rate [1/s] of the twin runs' difference above which a trial is unstable: an e-folding time of
#: 10 s, longer than any shipped scene's run, far faster than the decay of a stable loop's slowest mode
#: (about -1.4 /s on the fidelity scenes) and slower than a mode 5 % beyond its limit (~0.1 /s and up).
GROWTH_RATE = 0.1
#: Rise [-] of the seeded mode's amplitude over its seed beyond which a trial is unstable (module docstring):
#: a stable mode only decays from its seed; 10 % is above the few-percent wobble a nonlinear, moving loop
#: gives a slowly decaying mode's amplitude, and reached by a mode growing at 0.1 /s within a second.
MODE_GROWTH = 0.1
#: Relative difference [-] between measured and predicted beyond which the report explains it.
AGREEMENT = 0.2
#: Why a measurement on the closed loop may differ from the open-loop plant's prediction.
_CLOSED_LOOP = ("the closed loop is not the open-loop plant that was linearized: the controllers act on the "
                "limiting mode at every control instant (computed torque cancels the plant's own forces there)")
#: Integrator and fraction of its predicted limit used for the reference run.
REFERENCE_INTEGRATOR = "rk4"
REFERENCE_FRACTION = 0.25


@dataclass(frozen=True)
class StabilityRow:
    """Predicted and measured largest stable step of one integrator.

    Attributes:
        integrator: Registry name; ``order`` its order of accuracy.
        predicted_max_step_s: From the open-loop plant's linearization [s]; ``inf`` = no limit, ``0`` =
            unstable at every step.
        closed_loop_predicted_max_step_s: From the closed loop's linearized period map [s]
            (:mod:`~coopctrl.analysis.closed_loop_stability`); ``inf`` = stable up to the control period;
            ``nan`` = not computed.
        closed_loop_at_time_s: The instant [s] of the nominal run whose linearization sets it.
        limiting_mode_rad_s: ``|lambda|`` [rad/s] of the mode that sets the prediction (``nan`` if none).
        limiting_mode_damping_ratio: Its damping ratio ``-Re(lambda) / |lambda|`` [-].
        measured_max_step_s: Largest stable step found on the closed loop [s], or ``None`` (not measured).
        limited_by_control_period: True when ``h = T`` was stable: the measured value is a lower bound.
        first_unstable_step_s: The smallest step found unstable [s], or ``None``.
        failure: Why that trial failed (its reason, or the force growth it showed).
        trials: Number of closed-loop trials run.
        horizon_s: Simulated time of each trial [s].
        note: Anything that qualifies the figures.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    integrator: str
    order: int
    predicted_max_step_s: float
    closed_loop_predicted_max_step_s: float = math.nan
    closed_loop_at_time_s: float = math.nan
    limiting_mode_rad_s: float = math.nan
    limiting_mode_damping_ratio: float = math.nan
    measured_max_step_s: float | None = None
    limited_by_control_period: bool = False
    first_unstable_step_s: float | None = None
    failure: str = ""
    trials: int = 0
    horizon_s: float = 0.0
    note: str = ""

    @property
    def ratio(self) -> float | None:
        """``measured / predicted`` [-] when both are finite and positive and the measurement is not a bound."""
        p, m = self.predicted_max_step_s, self.measured_max_step_s
        if m is None or self.limited_by_control_period or not (0.0 < p < math.inf):
            return None
        return m / p

    @property
    def closed_loop_ratio(self) -> float | None:
        """``measured / closed-loop predicted`` [-] when both are finite and the measurement is not a bound."""
        p, m = self.closed_loop_predicted_max_step_s, self.measured_max_step_s
        if m is None or self.limited_by_control_period or not (0.0 < p < math.inf):
            return None
        return m / p


@dataclass(frozen=True)
class StabilityReport:
    """``omega_max`` of a scenario and the stability limits of its integrators.

    Attributes:
        scenario: Name of the scenario.
        state: The state linearized about and started from (``"loaded"`` or ``"unloaded"`` at t = 0).
        omega_max_rad_s: Highest elastic mode [rad/s] (generalized eigenvalues of K against Gamma).
        damping_ratio: Damping ratio of that mode [-], from the eigenvalues of ``A``
            (:func:`~coopctrl.analysis.modes.linear_modes`); ``modal_damping_ratio`` its classical modal one.
        fastest_eigenvalue: Eigenvalue of ``A`` of largest magnitude [1/s].
        stiffness_asymmetry: ``|K - K^T| / |K|`` [-] (dropped for ``omega``).
        unstable_stiffness_modes: Number of negative ``omega^2`` of the plant *without control* (static
            instabilities of the open-loop plant: the controllers may hold them).
        control_period_s: ``T`` [s], the longest step the loop can take.
        reference: ``{"integrator", "step_s", "status", "reason", "horizon_s", "elastic_energy_max_J"}`` of the
            reference run, or ``{}``.
        rows: One :class:`StabilityRow` per integrator.
        closed_loop_growing_modes: Modes of the closed loop that grow at a vanishing step at the start
            (:func:`closed_loop_growing_modes`; physical instabilities no step cures), ``None`` when the
            closed loop was not linearized (controllers off, or ``closed_loop=False``).
        controlled: False for a scene without control (``controllers.enabled = false``): the plant is the loop.
        object_modes: The object's modes on its interconnections with the contact nodes held, as the
            controllers leave them (:func:`coopctrl.tuning.elastic_modes.elastic_modes`): one dict per mode,
            slowest first, with ``omega_rad_s``, ``frequency_Hz``, ``damping_ratio`` and the object
            ``coordinate`` that moves most (a carried beam's first bending mode is its ``object_z``).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    scenario: str
    state: str
    omega_max_rad_s: float
    damping_ratio: float
    modal_damping_ratio: float
    fastest_eigenvalue: complex
    stiffness_asymmetry: float
    unstable_stiffness_modes: int
    control_period_s: float
    reference: dict = field(default_factory=dict)
    rows: tuple[StabilityRow, ...] = ()
    closed_loop_growing_modes: int | None = None
    controlled: bool = True
    object_modes: tuple = ()

    def row(self, integrator: str) -> StabilityRow:
        """The row of one integrator."""
        for r in self.rows:
            if r.integrator == integrator:
                return r
        raise KeyError(integrator)

    def to_dict(self) -> dict:
        """A JSON-ready dict (no NaN or infinity: ``None`` with a note instead)."""
        from coopctrl.results.summary import json_safe

        lam = self.fastest_eigenvalue
        rows = []
        for r in self.rows:
            notes = [r.note] if r.note else []
            if r.predicted_max_step_s == math.inf:
                notes.append("predicted: no limit (unconditionally stable on every mode)")
            if r.closed_loop_predicted_max_step_s == math.inf:
                notes.append("closed-loop prediction: stable up to the control period (null in JSON)")
            m = r.measured_max_step_s
            rows.append({
                "integrator": r.integrator,
                "order": r.order,
                "predicted_max_step_s": r.predicted_max_step_s,
                "closed_loop_predicted_max_step_s": r.closed_loop_predicted_max_step_s,
                "closed_loop_beyond_control_period": r.closed_loop_predicted_max_step_s == math.inf,
                "closed_loop_at_time_s": r.closed_loop_at_time_s,
                "measured_max_step_s": m,
                "limited_by_control_period": r.limited_by_control_period,
                "ratio_measured_predicted": r.ratio,
                "ratio_measured_closed_loop_predicted": r.closed_loop_ratio,
                "h_omega_max_at_measured": None if m is None else m * self.omega_max_rad_s,
                "limiting_mode_rad_s": r.limiting_mode_rad_s,
                "limiting_mode_damping_ratio": r.limiting_mode_damping_ratio,
                "first_unstable_step_s": r.first_unstable_step_s,
                "failure": r.failure,
                "trials": r.trials,
                "horizon_s": r.horizon_s,
                "note": "; ".join(notes),
            })
        return json_safe({
            "scenario": self.scenario,
            "state": self.state,
            "omega_max_rad_s": self.omega_max_rad_s,
            "damping_ratio": self.damping_ratio,
            "modal_damping_ratio": self.modal_damping_ratio,
            "fastest_mode_rad_s": abs(lam),
            "fastest_mode_damping_ratio": damping_ratio_of(lam) if lam != 0 else None,
            "stiffness_asymmetry": self.stiffness_asymmetry,
            "unstable_stiffness_modes": self.unstable_stiffness_modes,
            "closed_loop_growing_modes": self.closed_loop_growing_modes,
            "static_instabilities": self.static_instability_text(),
            "control_period_s": self.control_period_s,
            "object_modes": list(self.object_modes),
            "reference": self.reference,
            "rows": rows,
        })

    def static_instability_text(self) -> str:
        """What the negative stiffness eigenvalues mean for this scene, in one phrase.

        They are the plant's without control: where the controllers hold them (the closed loop grows
        no mode at a vanishing step) the run is not unstable and no step is at stake, so the phrase says
        so; where the closed loop does grow (a buckling grasp, or a scene without control) no step
        cures them."""
        n = self.unstable_stiffness_modes
        growing = self.closed_loop_growing_modes
        plant = f"the plant without control has {n} negative stiffness eigenvalue{'' if n == 1 else 's'}"
        if not self.controlled:
            return "none" if n == 0 else f"{n} (negative stiffness eigenvalues; the scene runs without control: no step cures them)"
        if growing is None:
            return "none" if n == 0 else (f"{n} in the plant without control (negative stiffness eigenvalues); the closed "
                                          "loop was not linearized: whether the controllers hold them is not known")
        if growing == 0:
            return "none" if n == 0 else f"none in the closed loop ({plant}; the controllers hold them)"
        return (f"{growing} growing mode{'s' if growing > 1 else ''} of the closed loop at a vanishing step ({plant}): "
                "physical, no step cures them")

    def object_modes_text(self) -> str:
        """The object's modes, slowest first: ``119.3 rad/s (18.99 Hz) object_z, ...``."""
        return ", ".join(f"{m['omega_rad_s']:.4g} rad/s ({m['frequency_Hz']:.4g} Hz) {m['coordinate']}"
                         for m in self.object_modes) or "-"

    def table(self) -> str:
        """The report as text: the modes, then one line per integrator."""
        lam = self.fastest_eigenvalue
        zeta_fast = damping_ratio_of(lam)
        lines = [
            f"scenario                    {self.scenario}",
            f"linearized at               {self.state} state at t = 0",
            f"omega_max_rad_s             {self.omega_max_rad_s:.6g}",
            f"damping ratio (that mode)   {self.damping_ratio:.3g}",
            f"fastest eigenvalue of A     |lambda| = {abs(lam):.6g} rad/s, zeta = {zeta_fast:.3g}",
            f"static instabilities        {self.static_instability_text()}",
            f"object modes (nodes held)   {self.object_modes_text()}",
            f"control period              {self.control_period_s:g} s (the longest step the loop can take)",
        ]
        ref = self.reference
        if ref:
            why = f" ({ref['reason']})" if ref["status"] != "ok" else ""
            lines.append(f"reference run               {ref['integrator']} at {ref['step_s']:.4g} s: {ref['status']}{why}")
        header = ("integrator", "order", "open-loop pred [s]", "closed-loop pred [s]", "measured [s]",
                  "meas/open", "meas/closed", "h*omega_max", "limiting mode (open loop)")
        body = []
        T = self.control_period_s
        for r in self.rows:
            pred = "no limit" if r.predicted_max_step_s == math.inf else f"{r.predicted_max_step_s:.4g}"
            c = r.closed_loop_predicted_max_step_s
            closed = "-" if math.isnan(c) else (f"> {T:g}" if c == math.inf else f"{c:.4g}")
            m = r.measured_max_step_s
            meas = "-" if m is None else (f">= {m:.4g}" if r.limited_by_control_period else f"{m:.4g}")
            ratio = "-" if r.ratio is None else f"{r.ratio:.3f}"
            cratio = "-" if r.closed_loop_ratio is None else f"{r.closed_loop_ratio:.3f}"
            hw = "-" if m is None else (f">= {m * self.omega_max_rad_s:.3g}" if r.limited_by_control_period
                                        else f"{m * self.omega_max_rad_s:.3g}")
            mode = ("-" if not math.isfinite(r.limiting_mode_rad_s)
                    else f"{r.limiting_mode_rad_s:.4g} rad/s, zeta {r.limiting_mode_damping_ratio:.2g}")
            body.append((r.integrator, str(r.order), pred, closed, meas, ratio, cratio, hw, mode))
        widths = [max(len(h), *(len(b[i]) for b in body)) if body else len(h) for i, h in enumerate(header)]
        fmt = lambda cells: "  ".join(c.ljust(w) for c, w in zip(cells, widths)).rstrip()  # noqa: E731
        lines += ["", fmt(header)] + [fmt(b) for b in body]
        notes = [f"{r.integrator}: {r.note}" for r in self.rows if r.note]
        if notes:
            lines += [""] + notes
        return "\n".join(lines)


# ---------------------------------------------------------------------- prediction
def closed_loop_growing_modes(lin) -> int:
    """Modes that the closed loop linearized in ``lin`` (a
    :class:`~coopctrl.analysis.closed_loop_stability.LoopLinearization`) grows on its own: eigenvalues of
    its period map ``Phi(h_0)`` outside the unit circle (by
    :data:`~coopctrl.analysis.closed_loop_stability.GROWTH_TOLERANCE`), with RK4 at ``h_0 = min(T, 0.01 /
    |lambda|_max)``, far below every step limit (the ``h_0`` of ``max_stable_step``). A negative stiffness
    of the plant that the controllers hold grows nothing here; a buckling grasp does, at every step."""
    lam = np.linalg.eigvals(lin.A)
    fastest = float(np.max(np.abs(lam))) if lam.size else 0.0
    T = lin.control_period
    h0 = min(T, 1e-2 / fastest) if fastest > 0 else T
    return lin.unstable_count(get_integrator(REFERENCE_INTEGRATOR), h0)


def limiting_mode(modes: ModalAnalysis, integrator) -> tuple[float, float]:
    """``(|lambda| [rad/s], zeta [-])`` of the mode that sets ``integrator``'s limit
    (:meth:`ModalAnalysis.limiting_mode`); ``(nan, nan)`` when no mode limits the step."""
    k = modes.limiting_mode(integrator)
    if k is None:
        return math.nan, math.nan
    v = complex(modes.eigenvalues[k])
    return abs(v), damping_ratio_of(v)


# ---------------------------------------------------------------------- measurement
def commutes(scheme) -> bool:
    """True when the scheme's one-step map is a function of ``h A`` (so steps of different sizes
    commute on a linear system): it has a scalar stability function."""
    try:
        scheme.eigenvalue_max_step(-1.0)
    except NotImplementedError:
        return False
    return True


def effective_step(scheme, h: float, control_period: float) -> float:
    """The step [s] a trial at ``h`` takes: ``h`` itself, or ``T / ceil(T / h)`` for a scheme that
    does not commute (see :meth:`ClosedLoop.set_step`)."""
    h = min(h, control_period)
    if commutes(scheme):
        return h
    return control_period / max(1, math.ceil(control_period / h * (1.0 - 1e-12)))


def run_trial(scenario, x0, integrator: str, h: float, horizon: float) -> dict:
    """One closed-loop trial: the scenario's loop with ``integrator`` at plant step ``h`` [s]."""
    from coopctrl.wiring import closed_loop

    scheme = get_integrator(integrator)
    T = scenario.simulation.control_period
    loop = closed_loop(scenario, integrator=scheme, step=min(h, T), uniform_step=not commutes(scheme))
    # a trial only needs to know that it failed: the loop's own reason, no closed-loop diagnosis (simulate's)
    return loop.run(x0, horizon)


def elastic_energy(plant, rec: dict) -> np.ndarray:
    """``Pi(Y(t))`` [J] of the interconnections at each recorded tick of a run."""
    return np.array([plant.elastic_potential(plant.node_poses(x)) for x in rec["x"]])


def perturbation_growth(rec_a: dict, rec_b: dict, nz: int) -> float:
    """Growth rate [1/s] of the difference of two runs: ``d_k = max |z_a - z_b|`` per tick, its envelope
    (maxima over windows of a tenth of the run), and the log-slope of that envelope from the middle
    window to the last. ``0`` when the runs are too short (fewer than 20 ticks)."""
    n = min(len(rec_a["t"]), len(rec_b["t"]))
    if n < 20:
        return 0.0
    d = np.max(np.abs(rec_a["x"][:n, :nz] - rec_b["x"][:n, :nz]), axis=1)
    w = n // 10
    env = np.array([np.max(d[i * w:(i + 1) * w]) for i in range(n // w)])
    mid, last = len(env) // 2, len(env) - 1
    t = rec_a["t"]
    span = float(t[min(last * w + w // 2, n - 1)] - t[mid * w + w // 2])
    if not (span > 0.0 and env[mid] > 0.0 and env[last] > 0.0):
        return 0.0 if env[last] == 0.0 else math.inf
    return math.log(env[last] / env[mid]) / span


def trial_verdict(plant, rec: dict, ref_energy: np.ndarray, twin: dict | None = None) -> tuple[bool, str]:
    """``(stable, why not)`` of a trial run against the reference run's elastic energy, and of its twin run
    ``twin`` (from a perturbed start) against it: the growth of their difference (module docstring)."""
    if rec["status"] != "ok":
        return False, rec["reason"] or rec["status"]
    if twin is not None:
        if twin["status"] != "ok":
            return False, f"the twin run (start moved by {TWIN_PERTURBATION:g}): {twin['reason'] or twin['status']}"
        rate = perturbation_growth(rec, twin, plant.nz)
        if rate > GROWTH_RATE:
            return False, (f"a perturbation of the start grows at {rate:.3g} /s over the second half of the run "
                           f"(bound {GROWTH_RATE:g} /s)")
    E = elastic_energy(plant, rec)
    n = min(len(E), len(ref_energy))
    if n == 0:
        return True, ""
    scale = float(np.max(ref_energy[:n]))
    worst = float(np.max(E[:n]))
    if not math.isfinite(worst):
        return False, "non-finite elastic energy"
    if worst > (1.0 + GROWTH_BOUND) ** 2 * scale:
        t = float(rec["t"][int(np.argmax(E[:n]))])
        return False, (f"elastic energy grew to {worst:.3g} J at t = {t:.4g} s (reference at most {scale:.3g} J; "
                       f"bound x{(1.0 + GROWTH_BOUND) ** 2:g})")
    return True, ""


def measure_max_step(scenario, integrator: str, predicted: float, ref_energy: np.ndarray, horizon: float, x0,
                     resolution: float = RESOLUTION, max_trials: int = 40, modes: ModalAnalysis | None = None,
                     longest: float | None = None, closed_loop_predicted: float = math.nan, progress=None,
                     probe=None) -> dict:
    """Bisect the largest stable plant step [s] of ``integrator`` on the scenario's closed loop.

    ``h = T`` is tried first (the cap); if unstable, a stable lower bracket is searched from
    ``min(predicted, T)`` (halving), then the bracket is bisected in ``log h`` until
    ``hi / lo - 1 <= resolution``. With ``modes`` (the linearization), each trial's horizon is
    :func:`growth_horizon` at its step, between ``horizon`` and ``longest`` [s] (``ref_energy`` must
    cover ``longest``). The lower bracket starts at the closed-loop prediction ``closed_loop_predicted``
    [s] when it is finite, else at the open-loop ``predicted`` [s]. With ``probe``
    (:class:`~coopctrl.analysis.closed_loop_stability.ModeProbe`) each trial's twin run starts moved along
    the least stable mode of the start's period map at that step, and that mode's amplitude is tracked.
    ``progress(message)`` is told of every trial. Returns ``{"measured", "limited", "first_unstable", "failure", "trials", "note"}``.
    """
    from coopctrl.scenario import build

    plant = build.build_plant(scenario)
    T = scenario.simulation.control_period
    scheme = get_integrator(integrator)
    trials = 0

    def stable(h):
        nonlocal trials
        trials += 1
        span = horizon
        if modes is not None and longest is not None and longest > horizon:
            span = growth_horizon(modes, scheme, h, T, horizon, longest, closed_loop_predicted)
        rec = run_trial(scenario, x0, integrator, h, span)
        mode = probe.mode(scheme, h) if probe is not None and rec["status"] == "ok" else None
        if mode is not None:
            v, w, _ = mode
            twin = run_trial(scenario, x0 + probe.seed(v, TWIN_PERTURBATION), integrator, h, span)
            verdict = trial_verdict(plant, rec, ref_energy)
            if verdict[0] and twin["status"] != "ok":
                verdict = False, f"the twin run (start moved along the least stable mode): {twin['reason']}"
            elif verdict[0]:
                rise = probe.growth(probe.amplitude(rec, twin, w))
                if rise > math.log1p(MODE_GROWTH):
                    verdict = False, (f"the mode the step destabilizes, seeded by {TWIN_PERTURBATION:g}, grew "
                                      f"{math.exp(rise):.3g} times (bound {1.0 + MODE_GROWTH:g})")
        elif probe is not None:  # the step moves no mode of the loop: the run and the energy bound decide
            verdict = trial_verdict(plant, rec, ref_energy)
        else:
            twin = (run_trial(scenario, seeded_start(x0, plant.nz, TWIN_PERTURBATION, seed=1), integrator, h, span)
                    if scenario.controllers.enabled and rec["status"] == "ok" else None)
            verdict = trial_verdict(plant, rec, ref_energy, twin)
        if progress:
            progress(f"{integrator}: trial {trials} at h = {h:.4g} s over {span:.3g} s: "
                     f"{'stable' if verdict[0] else 'unstable'}")
        return verdict

    ok, why = stable(T)
    if ok:
        return {"measured": T, "limited": True, "first_unstable": None, "failure": "", "trials": trials, "note": ""}
    hi, hi_why = T, why
    start = closed_loop_predicted if 0.0 < closed_loop_predicted < math.inf else predicted
    lo = min(start, T) if 0.0 < start < math.inf else 0.25 * T
    lo = effective_step(scheme, lo if lo < hi else 0.5 * hi, T)
    while True:
        if trials >= max_trials or horizon / lo > MAX_TRIAL_STEPS:
            return {"measured": None, "limited": False, "first_unstable": hi, "failure": hi_why, "trials": trials,
                    "note": f"no stable step found down to {hi:.3g} s (smaller steps would take more than "
                            f"{MAX_TRIAL_STEPS} plant steps per trial)"}
        ok, why = stable(lo)
        if ok:
            break
        hi, hi_why = lo, why
        lo = effective_step(scheme, 0.5 * lo, T)
    while hi / lo - 1.0 > resolution and trials < max_trials:
        mid = effective_step(scheme, math.sqrt(lo * hi), T)
        if mid in (lo, hi):  # no step T / n between them: resolved as far as the loop allows
            break
        ok, why = stable(mid)
        if ok:
            lo = mid
        else:
            hi, hi_why = mid, why
    return {"measured": lo, "limited": False, "first_unstable": hi, "failure": hi_why, "trials": trials, "note": ""}


def trial_horizon(control_period: float, predicted: float) -> float:
    """Simulated time [s] of each trial: at least :data:`MIN_PERIODS` control periods and
    :data:`MIN_STEPS` steps at a finite, positive predicted limit (capped at the control period), a
    whole number of periods."""
    periods = MIN_PERIODS
    if 0.0 < predicted < math.inf:
        periods = max(periods, math.ceil(MIN_STEPS * min(predicted, control_period) / control_period))
    return periods * control_period


def growth_horizon(modes: ModalAnalysis, scheme, h: float, control_period: float, shortest: float,
                   longest: float, closed_loop_limit: float = math.nan) -> float:
    """Simulated time [s] of a trial at step ``h``: ``shortest`` when both linearizations predict the
    step stable, else ``longest`` (the scenario's duration). Open loop: ``rho <= 1``, ``rho`` the
    spectral radius of the scheme's one-step matrix on the plant's linearization with its static
    instabilities removed; closed loop: ``h <= closed_loop_limit`` [s] (the closed-loop prediction,
    ``nan`` when not computed). A predicted growth is given the whole run to show, since the closed
    loop can grow more slowly than the open-loop prediction. Whole control periods."""
    from coopctrl.integrators.base import spectral_radius, without_static_instability

    h = effective_step(scheme, h, control_period)
    rho = spectral_radius(scheme.one_step_matrix(without_static_instability(modes.A), h))
    if not rho > 1.0 + 1e-12 and not h > closed_loop_limit * (1.0 + 1e-9):
        return shortest
    periods = math.ceil(max(shortest, longest) / control_period - 1e-9)
    return periods * control_period


def seeded_start(x, nz: int, size: float = SEED_PERTURBATION, seed: int = 0) -> np.ndarray:
    """``x`` with ``size * N(0, 1)`` added to each generalized coordinate ``z = x[:nz]`` (seeded)."""
    out = np.array(x, dtype=float)
    out[:nz] += size * np.random.default_rng(seed).standard_normal(nz)
    return out


# ---------------------------------------------------------------------- report
def stability_report(scenario, integrators=None, measure: bool = True, resolution: float = RESOLUTION,
                     closed_loop: bool = True, progress=None) -> StabilityReport:
    """Predicted (open and closed loop) and (optionally) measured stability limits of ``integrators``.

    Args:
        scenario: A :class:`~coopctrl.scenario.Scenario`.
        integrators: Registry names (default: every built-in scheme, :data:`~coopctrl.integrators.INTEGRATORS`).
        measure: Also bisect the limits on the closed loop (a few seconds per integrator).
        resolution: Relative resolution of the bisection [-].
        closed_loop: Also predict from the closed loop's linearized period map (a passive scene, with
            the controllers off, has none: its rows keep ``nan``).
        progress: Optional ``progress(message)`` called as the work advances (the CLI prints it on stderr).
    """
    from coopctrl.errors import ScenarioError
    from coopctrl.scenario import SensorsConfig, build

    say = progress or (lambda message: None)
    names = list(INTEGRATORS) if integrators is None else list(integrators)
    for name in names:
        get_integrator(name)  # an unknown name is a ScenarioError listing the valid ones
    if not names:
        raise ScenarioError("integrators", names, "at least one integrator name")
    plant = build.build_plant(scenario)
    x_start = build.initial_state(scenario)
    modes = linear_modes(plant, x_start)
    say(f"linearized the plant: omega_max = {modes.omega_max:.6g} rad/s")
    from coopctrl.tuning.elastic_modes import elastic_modes

    held = elastic_modes(plant, x_start)
    object_modes = tuple({"omega_rad_s": float(w), "frequency_Hz": float(w) / (2 * math.pi), "damping_ratio": float(z),
                          "coordinate": held.dominant_coordinate(k)}
                         for k, (w, z) in enumerate(zip(held.natural_frequencies, held.damping_ratios)))
    x0 = seeded_start(x_start, plant.nz)
    T = scenario.simulation.control_period
    predicted = {name: modes.predicted_max_step(get_integrator(name)) for name in names}

    reference: dict = {}
    ref_rec = None
    if measure:
        p_rk4 = modes.predicted_max_step(get_integrator(REFERENCE_INTEGRATOR))
        h_ref = min(T, REFERENCE_FRACTION * p_rk4) if 0.0 < p_rk4 < math.inf else T
        horizon = max(trial_horizon(T, p) for p in predicted.values())
        # the trials may run as long as the scenario (growth_horizon): the reference covers that
        longest = max(horizon, scenario.simulation.control_steps * T)
        ref_rec = run_trial(scenario, x0, REFERENCE_INTEGRATOR, h_ref, longest)
        ref_energy = elastic_energy(plant, ref_rec)
        reference = {"integrator": REFERENCE_INTEGRATOR, "step_s": h_ref, "status": ref_rec["status"],
                     "reason": ref_rec["reason"], "horizon_s": longest,
                     "elastic_energy_max_J": float(np.max(ref_energy)) if ref_energy.size else 0.0}
        say(f"reference run ({REFERENCE_INTEGRATOR} at {h_ref:.4g} s over {longest:.3g} s): {ref_rec['status']}")

    closed: dict = {}
    probe = None
    growing = None
    if closed_loop and scenario.controllers.enabled:
        from coopctrl.analysis.closed_loop_stability import (LoopLinearizer, ModeProbe, closed_loop_limits,
                                                              linearizations)

        exact = scenario.sensors == SensorsConfig()
        record = ref_rec if ref_rec is not None and exact and ref_rec["status"] == "ok" else None
        try:
            lins = linearizations(scenario, x_start, record=record, progress=say)
            closed = closed_loop_limits(lins, names, progress=say)
            probe = ModeProbe(LoopLinearizer(scenario), lins[0])
            growing = closed_loop_growing_modes(lins[0])
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            say(f"closed-loop prediction not available: {exc}")
            closed, probe, growing = {}, None, None

    rows = []
    for name in names:
        scheme = get_integrator(name)
        p = predicted[name]
        c = closed[name].max_step_s if name in closed else math.nan
        w, z = limiting_mode(modes, scheme)
        row = dict(integrator=name, order=scheme.order, predicted_max_step_s=p, limiting_mode_rad_s=w,
                   limiting_mode_damping_ratio=z, closed_loop_predicted_max_step_s=c,
                   closed_loop_at_time_s=closed[name].at_time_s if name in closed else math.nan)
        notes = []
        if p == 0.0:
            notes.append(f"open-loop prediction 0: the mode at {w:.4g} rad/s (zeta {z:.2g}) grows at every step in the "
                         "open-loop linearization (explicit Euler has no stable step on an undamped mode)")
        if measure:
            if ref_rec["status"] != "ok":
                notes.append("not measured: the reference run failed (see reference)")
            else:
                horizon = trial_horizon(T, p)
                # h = T is tried first: an unconditionally stable scheme normally stops there
                got = measure_max_step(scenario, name, p, ref_energy, horizon, x0, resolution, modes=modes,
                                       longest=longest, closed_loop_predicted=c, progress=say, probe=probe)
                row.update(measured_max_step_s=got["measured"], limited_by_control_period=got["limited"],
                           first_unstable_step_s=got["first_unstable"], failure=got["failure"],
                           trials=got["trials"], horizon_s=horizon)
                if got["note"]:
                    notes.append(got["note"])
                measured = got["measured"]
                say(f"{name}: measured {'>= ' if got['limited'] else ''}{measured if measured is None else f'{measured:.4g} s'}")
                if got["limited"] and 0.0 < c < T:
                    notes.append(f"stable at the control period although the closed loop is predicted unstable above "
                                 f"{c:.3g} s: the mode grows too slowly to show within the scenario's run")
                elif measured is not None and not got["limited"] and 0.0 < c < math.inf and not (
                        1.0 - AGREEMENT <= measured / c <= 1.0 + AGREEMENT):
                    notes.append(f"measured / closed-loop predicted = {measured / c:.3g}")
                if measured is not None and not got["limited"] and c == math.inf:
                    notes.append("the closed-loop period map is stable up to the control period, yet the trial above "
                                 f"{measured:.3g} s failed: {got['failure']}")
                if measured is not None and not got["limited"] and 0.0 < p < math.inf and not (
                        1.0 - AGREEMENT <= measured / p <= 1.0 + AGREEMENT):
                    notes.append(f"measured / open-loop predicted = {measured / p:.3g}: {_CLOSED_LOOP}")
        rows.append(StabilityRow(note="; ".join(notes), **row))
    lam = modes.fastest_eigenvalue
    return StabilityReport(
        scenario=scenario.name, state=scenario.simulation.start, omega_max_rad_s=modes.omega_max,
        damping_ratio=modes.damping_ratio, modal_damping_ratio=modes.modal_damping_ratio, fastest_eigenvalue=lam, stiffness_asymmetry=modes.stiffness_asymmetry,
        unstable_stiffness_modes=modes.unstable_stiffness_modes, control_period_s=T, reference=reference,
        rows=tuple(rows), closed_loop_growing_modes=growing, controlled=scenario.controllers.enabled,
        object_modes=object_modes)
