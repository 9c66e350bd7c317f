"""Why a run stopped: the reason a failed run reports, from the evidence the loop collected.

When a tick stops the run (the Euler-angle band, a divergence guard, a numerical failure of the
plant, a QP failure past its policy), the driver (:mod:`coopctrl.loop.run`) hands the evidence
to :func:`stop_reason`: the exception, the tick, the recorded states, the last good state, the
torque saturation so far and the events. It returns ``(status, reason)`` and appends the failure's
event:

- **Euler-angle singularity**: a node entered the band (:class:`~coopctrl.loop.euler_band.NearSingularity`),
  or the plant failed while a node was within twice the band's margin: named, with the fix (never a
  smaller step);
- **QP failure**: the solver's cause, and the held splits before it;
- **divergence**: what left its bounds and when, then its causes (:func:`divergence_reason`), and a
  suggested step only when the step is the cause. When the step limit that decides it belongs to a mode
  stiffened by the Euler-angle chart, that is named instead (:func:`chart_stiffening`).

The run's stop carries its raw facts. :func:`stop_reason` records them in the record, as a
:class:`Stop` (``LoopRecord.stop``): the exception, the tick, the state a few ticks before the failure,
the start, the Euler-chart finding and the evidence (saturation, events). The loop's own reason judges a
divergence's causes by what the loop knows: the static instability, the held QP splits, and the step
against the plant's open-loop predicted limit (:func:`open_loop_causes`; or the loop's ``failure_causes``
part when it was built with one). The closed loop's predicted step limit needs the scenario: it
linearizes a loop built from it (:mod:`coopctrl.analysis.closed_loop_stability`), the analysis layer,
which builds loops and so stands above them. The loop therefore imports nothing of ``coopctrl.analysis``
and holds no scenario: :func:`coopctrl.simulator.simulate` diagnoses the stop afterwards
(:func:`coopctrl.analysis.diagnosis.diagnose_record`, through :func:`rediagnose` with
:func:`coopctrl.analysis.diagnosis.diagnose_failure`), and a loop run alone (a stability trial) keeps its
own reason. The diagnosis runs after the run, in Python, on the recorded states.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from coopctrl.errors import DivergenceError
from coopctrl.io.number_text import number_text
from coopctrl.loop.euler_band import (
    EULER_PITCH_MARGIN_DEG,
    NearSingularity,
    SingularityHit,
    chart_mode_share,
    closest_to_singularity,
    fix_hint,
    hit_from_plant_error,
    margin_cos,
)
from plants.errors import EulerSingularityError, PlantError

#: Control ticks before the failure at which a diverged run is diagnosed [-]: the state of the last
#: tick may already be far into the blow-up (an unstable mode grows geometrically), so its
#: linearization would not be the one that failed.
DIAGNOSIS_TICKS_BACK = 5


@dataclass(frozen=True)
class Diagnosis:
    """The causes found for a failed run.

    Attributes:
        causes: One phrase per cause found, the most fundamental first.
        step_is_cause: True when the step exceeds the predicted closed-loop limit.
        closed_loop_limit_s: That limit [s] (``inf``: none below the control period; ``nan``: not known).
    """

    causes: tuple[str, ...]
    step_is_cause: bool
    closed_loop_limit_s: float


@dataclass(frozen=True, eq=False)
class Stop:
    """The raw facts of a run's stop, recorded as ``LoopRecord.stop`` so that a diagnosis that knows more
    than the loop (the scenario's closed-loop step limit) can explain it after the run (:func:`rediagnose`).

    Attributes:
        status: ``"diverged"`` or ``"qp_failed"``.
        error: The exception that stopped the run.
        tick: The tick ``k`` that failed [-]; ticks_done: ``k_done``, the ticks recorded [-].
        time_s: ``k T`` [s].
        x0: The start state; x_back: the recorded state :data:`DIAGNOSIS_TICKS_BACK` ticks before the
            failure (the start when none was recorded), at ``t_back`` [s]; ``None`` for a stop whose
            reason does not depend on the causes (the Euler-angle singularity, a QP failure).
        chart: The Euler-angle chart's stiffening phrase (:func:`chart_stiffening`; ``""``: none).
        evidence: The saturation so far (``saturated_ticks``, ``saturated_joint_ticks``,
            ``saturation_first_time_s``, ``saturated_last_tick``) and ``events`` up to the stop.
        event: Index of the stop's own event in the record's ``events``.
        causes_decide: True when the reason depends on the divergence's causes (a divergence away from
            the Euler-angle singularity): the stops :func:`rediagnose` explains anew.
    """

    status: str
    error: BaseException
    tick: int
    ticks_done: int
    time_s: float
    x0: np.ndarray
    x_back: np.ndarray | None
    t_back: float
    chart: str
    evidence: dict
    event: int
    causes_decide: bool


def _integrator_name(loop) -> str:
    return getattr(loop.integrator, "name", type(loop.integrator).__name__)


def held_split_cause(events) -> str:
    """The load-distribution phrase when the QP failed and the last split was held, else ``""``."""
    held = [e for e in events if e[1] == "qp_held"]
    if not held:
        return ""
    return (f"load distribution: the QP failed on {len(held)} ticks from t = {held[0][0]:.4g} s and the loop held its "
            f"last feasible split ({held[0][2]})")


def static_instability(loop, x) -> str:
    """Why a run at state ``x`` (the loaded start) cannot stay bounded, if the physics says so; else ``""``.

    Checks the object's stiffness with the contact nodes held (:meth:`ElasticSystem.node_stiffness`):
    a negative eigenvalue [N/m] is a static instability of the grasp, whatever the step.
    """
    Y = loop.plant.node_poses(x)
    K0 = loop.plant.elastic.node_stiffness(Y, 0)
    npos = loop.npos
    ev, vec = np.linalg.eigh(K0[:npos, :npos])
    if ev[0] < 0:
        d = vec[:, 0] * np.sign(vec[np.argmax(np.abs(vec[:, 0])), 0])
        axes = "xyz" if npos == 3 else "xz"
        direction = ", ".join(f"{c}: {number_text(v, '+.2f')}" for c, v in zip(axes, d))
        return (f"the grasp is statically unstable: the object's translational stiffness has a negative "
                f"eigenvalue {ev[0]:.4g} N/m along ({direction}); central springs carry lateral load only "
                "through tension and squeeze makes their lateral stiffness negative, so the object buckles out "
                "of the grasp line (docs/model.md s.3). Use element = \"offset\" (shear stiffness) or less squeeze")
    return ""


def step_advice(loop, x0, x_fail=None) -> tuple[float | None, str]:
    """``(suggested step [s], advice)`` after a failure at step ``h``: when ``h`` exceeds the predicted
    limit at the start state or at a state ``x_fail`` shortly before the failure, half the smaller
    limit (which is below ``h``); otherwise no step and a sentence saying the step is not the likely
    cause."""
    limits = [loop.predicted_max_step(x0)]
    if x_fail is not None and np.all(np.isfinite(x_fail)):
        try:
            limits.append(loop.predicted_max_step(x_fail))
        except (PlantError, np.linalg.LinAlgError, ValueError):
            pass
    limit = min(limits)
    name = _integrator_name(loop)
    if limit == 0.0:
        return None, (f"{name} is unstable at every step on an undamped mode of this plant: use "
                      "symplectic_euler, rk4, or implicit_euler for stiff grasps")
    if loop.h > limit:
        return 0.5 * limit, ""
    return None, (f"the step h = {loop.h:.3g} s is within {name}'s predicted stability limit {limit:.3g} s, "
                  "so the step is not the likely cause")


def nearest_singularity(loop, x, t: float, x_good, t_good: float) -> SingularityHit:
    """The node closest to pitch +-90 deg in the failing state ``x`` (if finite) or the last good one."""
    plant = loop.plant
    hits = []
    for state, when in ((x, t), (x_good, t_good)):
        if np.all(np.isfinite(state)):
            try:
                hits.append(closest_to_singularity(plant.node_poses(state).reshape(-1, plant.p), when))
            except PlantError:
                pass
    return min(hits, key=lambda h: h.cos_theta) if hits else SingularityHit(0, 0.0, 1.0, t_good)


def singularity_reason(hit: SingularityHit, detail: str = "") -> str:
    """One line for a run stopped at the Euler-angle singularity."""
    after = f" (the integration then failed: {detail})" if detail else ""
    return (f"Euler-angle singularity at t = {hit.time:.6g} s: {hit.describe(with_time=False)}{after}; a smaller step does not "
            f"help: {fix_hint()}")


def chart_stiffening(loop, x_back, t_back: float, x0) -> str:
    """Why the step failed, if it is the Euler-angle chart; else ``""``.

    Blamed on the chart when, at the state ``x_back`` a few ticks before the failure (or else at the
    start state ``x0``), the step is beyond the integrator's predicted limit and the mode that sets
    that limit lives mostly (share > 1/2, :func:`~coopctrl.loop.euler_band.chart_mode_share`) on the
    Euler angles of nodes pitched beyond 45 deg: rotational stiffness and damping written in Euler-angle
    coordinates act on the inertia ``L^T I L``, which loses rank like ``cos^2(theta)`` (docs/model.md s.2),
    so such a mode stiffens like ``1 / cos^2(theta)`` on the way to the singularity.
    """
    for x, t in ((x_back, t_back), (x0, 0.0)):
        try:
            modes = loop.modes(x)
            limit = modes.predicted_max_step(loop.integrator)
            k = modes.limiting_mode(loop.integrator)
            if k is None or not loop.h > limit:
                continue
            share, hit = chart_mode_share(loop.plant, x, modes.eigenvectors[:, k])
        except (PlantError, np.linalg.LinAlgError, ValueError):
            continue
        if share > 0.5:
            break
    else:
        return ""
    hit = SingularityHit(hit.node, hit.theta, hit.cos_theta, t)
    return (f"approaching the Euler-angle singularity: {hit.describe()}; the mode that limits {_integrator_name(loop)} "
            f"there ({abs(modes.eigenvalues[k]):.4g} rad/s, {100 * share:.0f} % on the Euler angles of pitched nodes) "
            "is stiffened by the Euler-angle chart (rotational stiffness and damping in Euler-angle coordinates act "
            "on an inertia L^T I L that vanishes like cos^2(theta)); a smaller step only helps until the pitch "
            f"grows further; {fix_hint()}")


def open_loop_causes(loop, evidence: dict, k_done: int, t_fail: float, x_back, t_back: float, x0) -> Diagnosis:
    """The causes a loop finds without the closed-loop stability analysis: the static instability at the
    start, the held QP splits, and the step judged against the plant's open-loop predicted limit."""
    causes = [c for c in (static_instability(loop, x0), held_split_cause(evidence.get("events", ()))) if c]
    return Diagnosis(tuple(causes), bool(loop.h > loop.predicted_max_step(x0)), math.nan)


def divergence_reason(loop, exc, t_fail: float, x_back, x0, chart: str = "", evidence: dict | None = None,
                      k_done: int = 0, t_back: float = 0.0, causes=None) -> str:
    """One line: what left its bounds and when, then its causes checked against the run's ``evidence``
    (``causes``, else the loop's ``failure_causes``, else :func:`open_loop_causes`), and step advice only
    when the step is the cause (its closed-loop predicted limit at the start and at ``x_back``, a few ticks
    before the failure)."""
    causes_of = causes or getattr(loop, "failure_causes", None) or open_loop_causes
    try:
        diag = causes_of(loop, evidence or {}, k_done, t_fail, x_back, t_back, x0)
    except Exception:  # noqa: BLE001 - the diagnosis must never replace the failure it explains
        diag = Diagnosis((), loop.h > loop.predicted_max_step(x0), math.nan)
    if diag.step_is_cause:
        step, advice = step_advice(loop, x0, x_back)
        if step is None and advice.startswith("the step h"):  # within the open-loop limit: half the closed-loop one
            step, advice = 0.5 * min(diag.closed_loop_limit_s, 2.0 * loop.T), ""
    else:
        limit = diag.closed_loop_limit_s
        name = _integrator_name(loop)
        shown = (f"the closed loop's stable range (its linearization has no limit below the control period "
                 f"{loop.T:g} s)" if limit == math.inf else
                 f"{name}'s predicted closed-loop stability limit {limit:.3g} s" if not math.isnan(limit) else
                 f"{name}'s predicted stability limit {loop.predicted_max_step(x0):.3g} s")
        step, advice = None, f"the step h = {loop.h:.3g} s is within {shown}, so the step is not the likely cause"
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
                  f"{loop.max_deformation:g} m (a static deflection |F| / k: the interconnections are too soft for "
                  "the load); raise the stiffness, lower the load or raise max_deformation")
    causes = list(diag.causes)
    if causes and causes[0] == static_instability(loop, x0):  # static instability: the physics' own sentence
        reason = f"{reason}: {causes.pop(0)}"
    if causes:
        reason = f"{reason}; cause: " + "; ".join(causes)
    return reason


def rediagnose(loop, stop: Stop, causes) -> str | None:
    """The reason of the stop ``stop`` of a run of ``loop`` with the divergence's causes found by ``causes``
    (``(loop, evidence, k_done, t_fail, x_back, t_back, x0) -> Diagnosis``), or ``None`` when that
    reason does not depend on them (:attr:`Stop.causes_decide`). Run after the run (the loop is not
    touched; :func:`coopctrl.analysis.diagnosis.diagnose_record` writes the reason into the record)."""
    if not stop.causes_decide:
        return None
    return divergence_reason(loop, stop.error, stop.time_s, stop.x_back, stop.x0, stop.chart,
                             evidence=dict(stop.evidence), k_done=stop.ticks_done, t_back=stop.t_back, causes=causes)


def stop_reason(loop, exc, k: int, k_done: int, rec, x, x_good, t_good: float, x0, events,
                saturation: dict) -> tuple[str, str]:
    """``(status, reason)`` of a run of ``loop`` stopped at tick ``k`` by ``exc`` (after ``k_done`` recorded
    ticks), with its event appended to ``events`` and its raw facts recorded as ``rec["stop"]``
    (:class:`Stop`): the loop's own diagnosis, shared by the Python and compiled ticks.

    ``rec`` holds the recorded states ``x`` and times ``t``; ``x`` is the failing state, ``x_good`` the
    last state that passed the checks (at ``t_good`` [s]), ``x0`` the start; ``saturation``:
    ``saturated_ticks``, ``saturated_joint_ticks``, ``saturation_first_time_s`` and ``saturated_last_tick``
    so far (the diagnosis' evidence)."""
    from coopctrl.errors import InfeasibleLoad

    spatial = loop.space == "spatial"
    T = loop.T
    near = margin_cos(2.0 * EULER_PITCH_MARGIN_DEG)  # a failure this close is blamed on the singularity
    x_start = np.array(x0, dtype=float)
    facts = dict(error=exc, tick=int(k), ticks_done=int(k_done), time_s=k * T, x0=x_start, x_back=None, t_back=0.0,
                 chart="", evidence=dict(saturation, events=tuple(events)), causes_decide=False)
    if isinstance(exc, NearSingularity):
        status, reason = "diverged", singularity_reason(exc.hit)
        events.append((exc.hit.time, "euler_singularity", reason))
    elif isinstance(exc, (DivergenceError, PlantError)):
        status = "diverged"
        hit = nearest_singularity(loop, x, k * T, x_good, t_good) if spatial else None
        if isinstance(exc, EulerSingularityError) or (hit is not None and hit.cos_theta < near):
            if isinstance(exc, EulerSingularityError) and (hit is None or hit.cos_theta >= near):
                hit = hit_from_plant_error(exc, k * T)  # reached inside a control period
            reason = singularity_reason(hit, f"{exc}" if isinstance(exc, DivergenceError) else "")
            events.append((hit.time, "euler_singularity", reason))
        else:
            # the advice is taken a few ticks before the failure: the last good state may already be wild
            back = max(0, k_done - 1 - DIAGNOSIS_TICKS_BACK)
            x_back = np.array(rec["x"][back], dtype=float) if k_done else x_start
            t_back = float(rec["t"][back]) if k_done else 0.0
            chart = chart_stiffening(loop, x_back, t_back, x_start) if spatial else ""
            evidence = dict(saturation, events=events)
            reason = divergence_reason(loop, exc, k * T, x_back, x_start, chart, evidence=evidence, k_done=k_done,
                                       t_back=t_back)
            facts.update(x_back=x_back, t_back=t_back, chart=chart, causes_decide=True)
            events.append((getattr(exc, "time", k * T), "euler_singularity" if chart else "diverged", reason))
    elif isinstance(exc, InfeasibleLoad):
        held = held_split_cause(events)
        status, reason = "qp_failed", f"at t = {k * T:.6g} s: {exc}" + (f"; cause: {held}" if held else "")
        events.append((k * T, "qp_failed", str(exc)))
    else:
        raise TypeError(f"stop_reason: {type(exc).__name__} is not a stop of the loop") from exc
    rec["stop"] = Stop(status=status, event=len(events) - 1, **facts)
    return status, reason
