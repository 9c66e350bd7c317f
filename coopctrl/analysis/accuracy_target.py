"""An accuracy target: the cheapest integrator setting whose object position error meets it.

:func:`recommend` simulates a **prefix** of the scenario (:func:`prefix_duration`) with the
reference solution and with candidate settings, cheapest first, and returns the cheapest setting
whose predicted full-run error (its prefix error times its growth factor, below), multiplied by
the safety factor :data:`SAFETY_FACTOR`, is at most the target. ``coopctrl tradeoff SCENE
--target E`` prints it (as the ``--set`` lines to use); ``simulation.accuracy = E`` makes ``coopctrl run`` apply it (:meth:`Recommendation.apply`).

The prefix
----------
``prefix = min(duration, max(PREFIX_MIN_S, PREFIX_PERIODS T))``, rounded to whole control periods:
0.25 s at the shipped 1 ms periods. It must hold the start of the task (the trajectory's
acceleration, the loaded start's first transients: the error sources) and enough periods for the
global error to build up through the feedback (50 periods at the slowest period, 3 ms on
``stiff_grasp_extreme``); it must stay a small part of the run (the search runs up to a few dozen
candidates on it, plus the Python reference, 1 to 3 ms per period). The compiled runs over the
whole duration (below) cost about as much as the run itself each.

Growth after the prefix, and the safety factor
-----------------------------------------------
The prefix error underestimates the full run's: the error keeps growing after the prefix while
the motion goes on, by a factor that depends on the scene **and** the scheme. Measured with
``benchmarks/bench_accuracy_target.py`` (full-run error / prefix error over every candidate):
1 on ``gripping_immobile_object`` (the error is made in the first transient); over 604 settings of
six scenes median 1.5 to 2.5, 95th percentile 9 to 13, up to 42 (``stiff_grasp_extreme``) and 39 on
``planar_two_arm_lift`` (its motion
accelerates after 0.25 s; 1.5 for Euler, 7 for RK4, 39 for TR-BDF2 at a loose tolerance). No single factor serves both: 39 would cost a first-order scheme
39 times its step count where 1 suffices. So the growth is measured per candidate, without the
expensive reference: a **compiled quasi-reference** (``rk45`` at ``rtol`` 1e-10, atol 1e-12 m:
:data:`QUASI_REFERENCE`) runs the whole duration once; a candidate whose prefix error can meet the
target (the full-run error is at least the prefix error: it is a maximum over more instants) runs
the whole duration too, and its growth factor is ``g = max_run |y - y_q| / max_prefix |y - y_q|``
(``y_q``: the quasi-reference); its predicted full-run error is ``g * prefix error``. The
quasi-reference's own prefix error against the reference is checked: above 1 % of the target
(:data:`QUASI_SHARE`: it cannot resolve the growth), or if it fails, ``g`` falls back to
:data:`FALLBACK_GROWTH`. A setting is accepted when ``SAFETY_FACTOR * g * prefix_error <= target``
(the same for the force with ``--force-target``). :data:`SAFETY_FACTOR` = 1.05 covers the error of
the prediction, measured by the same benchmark (full-run error against the reference / predicted
error, over the candidates with a prefix error above 1e-9 m: 0.994 to 1.013 on planar_two_arm_lift,
contact_points_only, gripping_immobile_object, fidelity_planar and spatial_three_arm_carry, 488
candidates; 0.91 to 1.23 on stiff_grasp_extreme, 99 candidates), plus the quasi-reference's share;
a larger factor would make the search skip settings that meet the target (1 -> 2 substeps doubles
the cost). On those six scenes at targets 1e-3 to 1e-7 m the recommendation met the target over
the whole run in 30 of 30 cases.

The cost
--------
Candidates are ranked by **right-hand-side evaluations** of the plant over the prefix (the kernels'
exact counts, Newton iterations and finite-difference Jacobians included): the count is the same on
every machine and every repetition, so the same command recommends the same setting, whereas wall
times of runs a few milliseconds long move by tens of percent with the load of the machine; the
controller and the QP cost the same per control period in every candidate (same period). The
measured wall time is reported with it.

The candidates
--------------
Fixed-step schemes at ``h = T / n`` for ``n`` in :data:`SEARCH_SUBSTEPS` (ratios of at most 1.5
between neighbours after 1 -> 2, so that the first ``n`` meeting the target costs at most 1.5 times
the cheapest ``n`` that would) and error-controlled schemes at ``rtol`` in :data:`SEARCH_RTOLS`
(half decades: the cost of a scheme of order ``p`` grows as ``rtol^(-1/p)``, by at most
``10^(1/4) = 1.8`` per half decade for ``rk23`` and ``1.26`` for ``rk45``), ``atol = ATOL_PER_RTOL
rtol``. Each scheme is tried from its cheapest setting on, and dropped at the first setting that
meets the target or costs more than the best found so far (a tighter setting only costs more).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass, replace
from typing import Any, Callable, Sequence

from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator
from coopctrl.analysis.tradeoff import (ATOL_PER_RTOL, ReferenceFailed, ReferenceSummary, TradeoffRow, is_adaptive,
                                        make_integrator, mark_pareto, measured_row, parse_integrators, run_errors,
                                        run_loop, tolerances_of)
from coopctrl.compact_repr import compact_repr
from coopctrl.errors import CoopctrlError, ScenarioError

#: The prefix: at least this simulated time [s] ...
PREFIX_MIN_S = 0.25
#: ... and at least this many control periods (the whole run if shorter).
PREFIX_PERIODS = 50
#: ``SAFETY_FACTOR * growth * prefix error <= target`` (see the module docstring; the figures:
#: benchmarks/bench_accuracy_target.py).
SAFETY_FACTOR = 1.05
#: Growth factor when the quasi-reference cannot measure it: the largest full-run / prefix error
#: ratio measured on the shipped scenes (39 on planar_two_arm_lift), rounded up.
FALLBACK_GROWTH = 40.0
#: The compiled quasi-reference (scheme, rtol [-], atol [m]) that measures the growth after the prefix.
QUASI_REFERENCE = ("rk45", 1e-10, 1e-12)
#: The quasi-reference's prefix error may be at most this share of the target (it then moves the
#: predicted error by about as much: the safety factor covers it).
QUASI_SHARE = 0.01
#: Errors below this [m] (a few times the reference's own error) do not define a growth: the floor
#: of the growth's denominator.
GROWTH_FLOOR_M = 1e-11
#: The same floor for forces [N].
GROWTH_FLOOR_N = 1e-8
#: Fixed-step candidates ``h = T / n`` (neighbours at most 1.5 apart).
SEARCH_SUBSTEPS = (1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48, 64, 96, 128)
#: Error-controlled candidates' ``rtol`` [-] (half decades, 1e-2 to 1e-11).
SEARCH_RTOLS = tuple(float(f"{10 ** (-k / 2):.0e}") if k % 2 == 0 else float(f"{10 ** (-k / 2):.1e}")
                     for k in range(4, 23))
#: Search order: the schemes that are usually cheapest first, so that the others are cut early.
SEARCH_ORDER = ("rk4", "rk45", "rk23", "symplectic_euler", "implicit_midpoint", "trbdf2", "implicit_euler", "euler")
#: Targets [m] outside this range are refused (1e-12 m is the reference's own error; 1 m is no target).
TARGET_RANGE_M = (1e-12, 1.0)
#: Force targets [N] outside this range are refused.
FORCE_TARGET_RANGE_N = (1e-9, 1e6)


class TargetUnreachable(CoopctrlError, ArithmeticError):
    """No candidate setting meets the target on the prefix.

    Attributes:
        search: The :class:`TargetSearch` (its rows: every setting tried); best: its row with the
            smallest position error, or ``None`` when every candidate diverged.
    """

    def __init__(self, search: "TargetSearch"):
        self.search = search
        self.best = search.best_row()
        b = self.best
        need = f"{search.target_m:.3g} m" + (f" and {search.force_target_N:.3g} N" if search.force_target_N else "")
        if b is None:
            got = "every candidate setting diverged"
        else:
            force = f", force error {b.force_error_N:.3g} N" if b.force_error_N is not None else ""
            got = (f"the best error reached on the {search.prefix_s:.4g} s prefix is {b.position_error_m:.3g} m{force} "
                   f"({describe(b)}, {b.rhs_evaluations} rhs evaluations, {b.wall_time_s:.3g} s wall time)")
        super().__init__(f"no setting meets the target {need} with the safety factor {search.safety_factor:g}: {got}")


def check_target(value: Any, name: str = "target", low_high: tuple[float, float] = TARGET_RANGE_M,
                 unit: str = "m") -> float:
    """``value`` as a float in ``[low, high]`` [``unit``].

    Raises:
        ScenarioError: (a ``ValueError``) naming ``name``, for a non-number, non-finite or out-of-range value.
    """
    low, high = low_high
    number = float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else math.nan
    if not low <= number <= high:  # NaN fails
        raise ScenarioError(name, value, f"an error in [{low:g}, {high:g}] {unit} (a finite number > 0)")
    return number


def prefix_duration(simulation) -> float:
    """The simulated time [s] measured: ``min(duration, max(PREFIX_MIN_S, PREFIX_PERIODS T))`` in
    whole control periods ``T`` (see the module docstring)."""
    T = simulation.control_period
    periods = max(PREFIX_PERIODS, math.ceil(PREFIX_MIN_S / T - 1e-9))
    return min(simulation.control_steps, periods) * T


def describe(row) -> str:
    """``"rk4 at h = T/4 = 0.00025 s"`` or ``"rk45 at rtol 1e-06, atol 1e-08 m"``."""
    if row.substeps is None:
        return f"{row.integrator} at rtol {row.rtol:.3g}, atol {row.atol:.3g} m"
    return f"{row.integrator} at h = T/{row.substeps} = {row.step_s:.6g} s"


def settings_of(row) -> dict[str, Any]:
    """The override paths and values (as ``--set`` takes them) that select ``row``'s setting."""
    if row.substeps is None:
        return {"simulation.integrator": row.integrator, "simulation.rtol": row.rtol, "simulation.atol": row.atol}
    return {"simulation.integrator": row.integrator, "simulation.substeps": row.substeps}


@dataclass(frozen=True)
class Recommendation:
    """The cheapest setting found, and what it measured on the prefix.

    Attributes:
        row: Its :class:`~coopctrl.analysis.tradeoff.TradeoffRow` (errors on the prefix).
        prefix_s: The prefix [s]; safety_factor: the factor applied; target_m: the target [m];
        force_target_N: the force target [N], or ``None``.
    """

    __repr__ = compact_repr

    row: TradeoffRow
    prefix_s: float
    safety_factor: float
    target_m: float
    force_target_N: float | None = None
    prediction: dict | None = None

    @property
    def predicted_error_m(self) -> float | None:
        """Predicted full-run position error [m]: growth factor times prefix error."""
        return None if self.prediction is None else self.prediction["predicted_error_m"]

    @property
    def settings(self) -> dict[str, Any]:
        """``{"simulation.integrator": ..., ...}``: the overrides that select it."""
        return settings_of(self.row)

    def set_lines(self) -> list[str]:
        """``["--set simulation.integrator=rk4", "--set simulation.substeps=2"]``."""
        return [f"--set {k}={v if isinstance(v, str) else repr(v)}" for k, v in self.settings.items()]

    def apply(self, scenario):
        """``scenario`` with this setting (and no ``simulation.accuracy``: the choice is made)."""
        fields: dict[str, Any] = {"integrator": self.row.integrator, "accuracy": None}
        if self.row.substeps is None:
            fields.update(rtol=self.row.rtol, atol=self.row.atol)
        else:
            fields.update(substeps=self.row.substeps)
        return replace(scenario, simulation=replace(scenario.simulation, **fields))

    def sentence(self) -> str:
        """One line: what was chosen and why."""
        r = self.row
        force = f", force error {r.force_error_N:.3g} N" if r.force_error_N is not None else ""
        g = self.prediction["growth_position"] if self.prediction else None
        grown = "" if g is None else (f", predicted over the run {self.predicted_error_m:.3g} m (growth x{g:.3g})")
        return (f"chose {describe(r)}, the cheapest setting meeting the target {self.target_m:.3g} m"
                + (f" and {self.force_target_N:.3g} N" if self.force_target_N else "")
                + f" with the safety factor {self.safety_factor:g}: error on the first {self.prefix_s:.4g} s "
                f"{r.position_error_m:.3g} m{force}{grown}; cost {r.rhs_evaluations} rhs evaluations, "
                f"{r.wall_time_s:.3g} s wall time on the prefix")

    def to_dict(self) -> dict[str, Any]:
        """``{"set": {...}, "error_m", "force_error_N", "orientation_error_rad", "wall_time_s",
        "rhs_evaluations", "prefix_s", "safety_factor", "growth_position", "growth_force",
        "predicted_error_m", "predicted_force_error_N"}``: errors [m, N, rad] and wall time [s] measured
        on the prefix; the predictions for the whole run."""
        from coopctrl.results import json_safe

        r = self.row
        return json_safe({"set": self.settings, "error_m": r.position_error_m, "force_error_N": r.force_error_N,
                          "orientation_error_rad": r.orientation_error_rad, "wall_time_s": r.wall_time_s,
                          "rhs_evaluations": r.rhs_evaluations, "prefix_s": self.prefix_s,
                          "safety_factor": self.safety_factor, **(self.prediction or {})})


@dataclass(frozen=True)
class TargetSearch:
    """The settings tried on the prefix, and the recommendation (``None``: the target is unreachable).

    Attributes:
        scenario: Its name; target_m, force_target_N: the targets [m], [N] (or ``None``);
        prefix_s: The prefix [s]; safety_factor: the factor; reference: the
        :class:`~coopctrl.analysis.tradeoff.ReferenceSummary` of the prefix; rows: every setting
        tried, in the order tried; recommendation: the :class:`Recommendation` or ``None``;
        predictions: per row, its :data:`PREDICTION_FIELDS` (``None`` where not measured);
        quasi_reference: whether the growth was measured (else :data:`FALLBACK_GROWTH`).
    """

    __repr__ = compact_repr

    scenario: str
    target_m: float
    force_target_N: float | None
    prefix_s: float
    safety_factor: float
    reference: ReferenceSummary
    rows: tuple[TradeoffRow, ...]
    recommendation: Recommendation | None
    predictions: tuple[dict, ...] = ()
    quasi_reference: bool = False

    def best_row(self) -> TradeoffRow | None:
        """The completed row with the smallest position error (``None`` if none completed)."""
        done = [r for r in self.rows if r.status == "ok" and r.position_error_m is not None]
        return min(done, key=lambda r: (r.position_error_m, r.rhs_evaluations)) if done else None

    def to_dict(self) -> dict[str, Any]:
        from coopctrl.results import json_safe

        return json_safe({"scenario": self.scenario, "target_m": self.target_m,
                          "force_target_N": self.force_target_N, "prefix_s": self.prefix_s,
                          "safety_factor": self.safety_factor, "cost": "rhs_evaluations",
                          "quasi_reference": self.quasi_reference, "reference": self.reference.to_dict(),
                          "rows": [{**r.to_dict(), **p} for r, p in zip(self.rows, self.predictions)],
                          "recommendation": None if self.recommendation is None else self.recommendation.to_dict()})

    def text(self) -> str:
        """The recommendation as text: the sentence and the ``--set`` lines (or why there is none)."""
        if self.recommendation is None:
            return str(TargetUnreachable(self))
        rec = self.recommendation
        return "\n".join([f"target {self.target_m:.3g} m on {self.scenario}: {rec.sentence()}", "use:",
                          *(f"  {line}" for line in rec.set_lines())])


def meets(row: TradeoffRow, target_m: float, force_target_N: float | None, factor: float,
          force_factor: float | None = None) -> bool:
    """Whether a prefix row meets the targets once its errors are multiplied by ``factor`` (the
    force's by ``force_factor``, default ``factor``)."""
    if row.status != "ok" or row.position_error_m is None:
        return False
    if factor * row.position_error_m > target_m:
        return False
    force_factor = factor if force_factor is None else force_factor
    return force_target_N is None or (row.force_error_N is not None
                                      and force_factor * row.force_error_N <= force_target_N)


def growth(run, quasi, ticks: int) -> tuple[float, float]:
    """``(g_position, g_force)``: max over the run / max over the first ``ticks + 1`` instants of the
    difference of ``run`` from the quasi-reference ``quasi`` (floors :data:`GROWTH_FLOOR_M`, ``_N``)."""
    import numpy as np

    npos = 2 if run.Y0.shape[1] == 3 else 3
    dp = np.linalg.norm(run.Y0[:, :npos] - quasi.Y0[:, :npos], axis=1)
    df = np.max(np.linalg.norm(run.forces - quasi.forces, axis=-1), axis=1) if run.forces.size else np.zeros(len(dp))
    out = []
    for d, floor in ((dp, GROWTH_FLOOR_M), (df, GROWTH_FLOOR_N)):
        out.append(max(1.0, float(np.max(d)) / max(float(np.max(d[:ticks + 1])), floor)))
    return out[0], out[1]


#: Per-row fields of the search beyond a TradeoffRow's: the growth factors and predicted full-run errors.
PREDICTION_FIELDS = ("growth_position", "growth_force", "predicted_error_m", "predicted_force_error_N")


def _row(fields: dict) -> TradeoffRow:
    return TradeoffRow(**{k: v for k, v in fields.items() if k not in PREDICTION_FIELDS})


def _head(run, ticks: int):
    """The first ``ticks + 1`` control instants of a :class:`~coopctrl.analysis.tradeoff.LoopRun`."""
    k = ticks + 1
    return replace(run, t=run.t[:k], Y0=run.Y0[:k], forces=run.forces[:k])


def candidates(name: str) -> list[tuple[int | None, float | None]]:
    """``(substeps, rtol)`` of a scheme's candidates, cheapest first."""
    if is_adaptive(name):
        return [(None, r) for r in SEARCH_RTOLS]
    return [(n, None) for n in SEARCH_SUBSTEPS]


def recommend(scenario, target_m: float, force_target_N: float | None = None,
              integrators: Sequence[str] | None = None, safety_factor: float = SAFETY_FACTOR,
              reference: ReferenceConfig | None = None, prefix_s: float | None = None,
              progress: Callable[[str], None] | None = None) -> TargetSearch:
    """Search the cheapest setting that meets ``target_m`` (see the module docstring).

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario`.
        target_m: Object position error target [m], in :data:`TARGET_RANGE_M`.
        force_target_N: Optional contact force error target [N], in :data:`FORCE_TARGET_RANGE_N`.
        integrators: Schemes to consider (default: every fixed-step and error-controlled one).
        safety_factor: ``>= 1``; default :data:`SAFETY_FACTOR`.
        reference: The reference's :class:`ReferenceConfig` (default DOP853, rtol 1e-11).
        prefix_s: Simulated time measured [s]; default :func:`prefix_duration`.
        progress: Called with a short label before each run.

    Returns:
        The :class:`TargetSearch`; its ``recommendation`` is ``None`` when no candidate meets the target.

    Raises:
        ScenarioError: for a bad target, scheme or safety factor.
        ReferenceFailed: when the reference does not complete on the prefix.
    """
    import numpy as np

    from coopctrl.errors import InfeasibleLoad
    from coopctrl.scenario import build

    target_m = check_target(target_m)
    if force_target_N is not None:
        force_target_N = check_target(force_target_N, "force_target", FORCE_TARGET_RANGE_N, "N")
    names = parse_integrators(list(integrators) if integrators is not None else None)
    names = tuple(sorted(names, key=lambda n: SEARCH_ORDER.index(n) if n in SEARCH_ORDER else len(SEARCH_ORDER)))
    factor = float(safety_factor) if isinstance(safety_factor, (int, float)) and not isinstance(safety_factor, bool) \
        else math.nan
    if not 1.0 <= factor <= 1e3:
        raise ScenarioError("safety_factor", safety_factor, "a number in [1, 1000]")
    sim = scenario.simulation
    T = sim.control_period
    prefix = prefix_duration(sim) if prefix_s is None else max(1, round(float(prefix_s) / T)) * T
    config = reference if reference is not None else ReferenceConfig()
    try:
        x0 = build.initial_state(scenario)
    except InfeasibleLoad as exc:
        raise ReferenceFailed("qp_failed", f"at t = 0 s (loaded start): {exc}") from None
    if progress:
        progress(f"reference ({config.method}), {prefix:.4g} s")
    ref = run_loop(scenario, x0, ReferenceIntegrator(config), 1, prefix)
    if ref.status != "ok":
        raise ReferenceFailed(ref.status, ref.reason)
    npos = 2 if ref.Y0.shape[1] == 3 else 3
    span = float(np.max(np.linalg.norm(ref.Y0[:, :npos] - ref.Y0[0, :npos], axis=1)))
    force_scale = float(np.max(np.linalg.norm(ref.forces, axis=-1))) if ref.forces.size else 0.0
    ticks = int(round(prefix / T))
    full = sim.control_steps * T
    quasi = None
    if full > prefix:  # the growth after the prefix, measured against the compiled quasi-reference
        if progress:
            progress("quasi-reference over the run")
        scheme, q_rtol, q_atol = QUASI_REFERENCE
        quasi = run_loop(scenario, x0, make_integrator(scheme, q_rtol), 1, full)
        if quasi.status != "ok":
            quasi = None
        else:
            q_err = run_errors(_head(quasi, ticks), ref)
            if q_err["position_error_m"] > QUASI_SHARE * target_m or (
                    force_target_N is not None and q_err["force_error_N"] > QUASI_SHARE * force_target_N):
                quasi = None  # it cannot resolve the growth at this target
    rows: list[dict] = []
    best: dict | None = None
    for name in names:
        for n, rtol in candidates(name):
            if progress:
                progress(f"{name} rtol {rtol:g}" if n is None else f"{name} T/{n}")
            run = run_loop(scenario, x0, make_integrator(name, rtol), n or 1, prefix)
            row = measured_row(run, ref, name, T, n, rtol)
            row.update(growth_position=None, growth_force=None, predicted_error_m=None, predicted_force_error_N=None)
            rows.append(row)
            if best is not None and row["rhs_evaluations"] >= best["rhs_evaluations"]:
                break  # a tighter setting of this scheme only costs more
            if not meets(_row(row), target_m, force_target_N, factor):
                continue  # the full-run error is at least the prefix error
            g_pos = g_force = 1.0
            if full > prefix:
                whole = run_loop(scenario, x0, make_integrator(name, rtol), n or 1, full)
                if whole.status != "ok":
                    row.update(status=whole.status, reason=f"after the prefix: {whole.reason}")
                    continue
                g_pos, g_force = growth(whole, quasi, ticks) if quasi is not None else (FALLBACK_GROWTH,) * 2
            row.update(growth_position=g_pos, growth_force=g_force,
                       predicted_error_m=g_pos * row["position_error_m"],
                       predicted_force_error_N=None if row["force_error_N"] is None else g_force * row["force_error_N"])
            if meets(_row(row), target_m, force_target_N, factor * g_pos, factor * g_force):
                best = row
                break
    mark_pareto(rows)
    final = tuple(_row(r) for r in rows)
    predictions = tuple({k: r[k] for k in PREDICTION_FIELDS} for r in rows)
    chosen = None
    if best is not None:
        row = final[next(i for i, r in enumerate(rows) if r is best)]
        chosen = Recommendation(row, prefix, factor, target_m, force_target_N,
                                predictions[next(i for i, r in enumerate(rows) if r is best)])
    return TargetSearch(scenario=scenario.name, target_m=target_m, force_target_N=force_target_N, prefix_s=prefix,
                        safety_factor=factor, reference=ReferenceSummary(config, ref.wall_time_s, ref.rhs_evaluations,
                                                                         force_scale, span),
                        rows=final, recommendation=chosen, predictions=predictions,
                        quasi_reference=quasi is not None)


__all__ = ["ATOL_PER_RTOL", "PREFIX_MIN_S", "PREFIX_PERIODS", "SAFETY_FACTOR", "SEARCH_RTOLS", "SEARCH_SUBSTEPS",
           "Recommendation", "TargetSearch", "TargetUnreachable", "check_target", "describe", "meets",
           "choose_setting", "prefix_duration", "recommend", "settings_of", "tolerances_of"]


def choose_setting(scenario, progress: Callable[[str], None] | None = None):
    """``simulation.accuracy``: the scenario with the recommended setting, and the :class:`Recommendation`.

    Raises:
        ValueError: the scenario has no ``simulation.accuracy``.
        TargetUnreachable: no candidate meets it; ReferenceFailed: the reference failed on the prefix.
    """
    target = scenario.simulation.accuracy
    if target is None:
        raise ValueError("simulation.accuracy is not set: there is no target to choose a setting for")
    if progress is None and sys.stderr.isatty():  # a search of many runs: its progress on a terminal
        def progress(label: str) -> None:
            print(f"coopctrl: simulation.accuracy: {label}", file=sys.stderr, flush=True)
    search = recommend(scenario, target, progress=progress)
    if search.recommendation is None:
        raise TargetUnreachable(search)
    return search.recommendation.apply(scenario), search.recommendation
