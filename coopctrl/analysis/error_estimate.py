"""An error bar on a run: rerun at a tighter setting and compare (``coopctrl run --estimate-error``).

:func:`estimate_error` runs the scenario's closed loop twice from the same initial state: at its
own setting (the run being judged; bit for bit the run of ``coopctrl run``) and at a tighter one,

* fixed step ``h = T / n``: the same scheme at ``h / 2`` (``2 n`` substeps);
* error-controlled (``rk23``, ``rk45``, ``trbdf2``): a fixed-step reference, RK4 at ``h_b = T / (2 n_a)``,
  with ``h_a = T / n_a`` the smaller of half the run's mean step and its smallest accepted step
  (:func:`reference_substeps`), and RK4 at ``h_a`` to bound that reference's own error,

and reports, each the maximum over the control instants ``t_k`` of the run, the difference of the
two runs in the object position ``|r_0 - r_0'|`` [m], orientation (angle of the relative rotation)
[rad] and contact forces ``max_i |f_i - f_i'|`` [N] (the same metrics as ``coopctrl tradeoff``).

Why the difference estimates the cheap run's error (Richardson's argument): the controller is
sampled at the same instants in both runs, so the two differ by their integration errors alone.
A fixed-step scheme of order ``p`` has a global error ``e(h) = C h^p + O(h^(p+1))``, so
``y_h - y_(h/2) = e(h) - e(h/2) = (1 - 2^-p) e(h)``: the estimate is the difference times
``2^p / (2^p - 1)`` (2 for Euler, 4/3 for the implicit midpoint rule, 16/15 for RK4). An
error-controlled scheme's global error is not proportional to its tolerance in this closed loop
(on ``stiff_grasp_extreme`` 100 times smaller tolerances leave far more than 1 % of the error), so its bar
is measured against the fixed-step reference instead. By the triangle
inequality at each instant, ``|y - y*| <= |y - y_b| + |y_b - y*|``, and RK4's own error at ``h_b`` is
``|y_a - y_b| / 15`` (Richardson, order 4): the bar is ``max |y - y_b| + max |y_a - y_b| / 15``, an upper
bound of the run's error whenever RK4 is in its asymptotic range at ``h_a`` (which the second term
checks: it is small against the first when the reference is much more accurate than the run).
The estimate is only as good as these asymptotics: it holds when the tighter run is much more
accurate than the cheap one (the step in the asymptotic range, no step-size-dependent event such
as a divergence or a torque saturation switching on in one run only). An error-controlled run whose
steps are all whole control periods (the tolerance is not what limits them) may take the very same
steps at the tighter tolerances: there is then no estimate, and the reason says so. It says nothing about the
model's error (the plant against the real arms), only the integration's.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from coopctrl.compact_repr import compact_repr

#: Largest number of substeps of the tighter fixed-step run (the schema's ``simulation.substeps`` limit).
MAX_SUBSTEPS = 10000
#: The fixed-step scheme of an error-controlled run's reference, and its order.
REFERENCE_SCHEME, REFERENCE_ORDER = "rk4", 4


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated global error of a run (see the module docstring).

    Attributes:
        position_m: Object position error [m]; orientation_rad: object orientation error [rad];
        force_N: contact force error [N]: each the maximum over the run of the difference of the two
            runs, times ``richardson_factor``. ``None`` when a run did not complete (``reason`` says).
        setting: The cheap run's setting; tighter_setting: the tighter run's (text).
        richardson_factor: ``2^p / (2^p - 1)`` (fixed step of order ``p``), or ``1`` (error-controlled:
            the difference to the reference plus the reference's own error, module docstring).
        tighter_wall_time_s: Wall time [s] of the tighter run.
        reason: Why there is no estimate, or ``""``.
    """

    __repr__ = compact_repr

    position_m: float | None
    orientation_rad: float | None
    force_N: float | None
    setting: str
    tighter_setting: str
    richardson_factor: float
    tighter_wall_time_s: float
    reason: str = ""

    def to_dict(self) -> dict[str, Any]:
        """Flat summary keys (``estimated_position_error_m``, ...)."""
        return {"estimated_position_error_m": self.position_m, "estimated_orientation_error_rad": self.orientation_rad,
                "estimated_force_error_N": self.force_N, "error_estimate_setting": self.setting,
                "error_estimate_tighter_setting": self.tighter_setting,
                "error_estimate_richardson_factor": self.richardson_factor,
                "error_estimate_tighter_wall_time_s": self.tighter_wall_time_s,
                "error_estimate_reason": self.reason}

    def lines(self) -> list[str]:
        """Text lines for the summary table."""
        if self.position_m is None:
            return [f"{'estimated error'.ljust(28)}  - ({self.reason})"]
        return [f"{'estimated position error'.ljust(28)}  {self.position_m:.3g} m",
                f"{'estimated orientation error'.ljust(28)}  {self.orientation_rad:.3g} rad",
                f"{'estimated force error'.ljust(28)}  {self.force_N:.3g} N",
                f"{'error estimated against'.ljust(28)}  {self.tighter_setting} "
                + (f"(x{self.richardson_factor:.4g}, Richardson)" if self.richardson_factor != 1.0 else
                   "(its own error added, Richardson)")]


def _settings(sim) -> tuple[Any, Any, int, int, str, str, float]:
    """The cheap and tighter integrators of a fixed-step run, their substeps, their descriptions and the
    factor (an error-controlled run's reference is chosen after its run: :func:`reference_substeps`)."""
    from coopctrl.integrators import get_integrator

    if sim.adaptive:
        cheap = get_integrator(sim.integrator, rtol=sim.rtol, atol=sim.atol, atol_velocity=sim.atol_velocity,
                               min_step=sim.min_step)
        return (cheap, None, 1, 1, f"{sim.integrator} at rtol {cheap.rtol:.3g}, atol {cheap.atol:.3g} m", "", 1.0)
    cheap, tight = get_integrator(sim.integrator), get_integrator(sim.integrator)
    n = sim.substeps
    n2 = min(2 * n, MAX_SUBSTEPS)
    p = int(cheap.order)
    T = sim.control_period
    return (cheap, tight, n, n2, f"{sim.integrator} at h = T/{n} = {T / n:.6g} s",
            f"{sim.integrator} at h = T/{n2} = {T / n2:.6g} s", 2.0 ** p / (2.0 ** p - 1.0))


def reference_substeps(steps, control_period: float) -> int:
    """``n_a`` [-] of an error-controlled run's reference (module docstring) from its per-tick step
    statistics ``steps`` (``LoopRecord.integration_steps``: accepted, rejected, evaluations, smallest
    step [s]): ``h_a = T / n_a`` at most half the mean accepted step and at most the smallest one, ``n_a``
    at most ``MAX_SUBSTEPS / 2`` (``h_b = h_a / 2`` is the reference)."""
    T = float(control_period)
    accepted = int(np.sum(steps[:, 0])) if steps is not None and len(steps) else 0
    if not accepted:
        return 1
    advanced = steps[:, 0] > 0
    mean = np.count_nonzero(advanced) * T / accepted
    smallest = float(np.min(steps[advanced, 3]))
    h = min(0.5 * mean, smallest, T)
    return int(min(MAX_SUBSTEPS // 2, max(1, math.ceil(T / h * (1.0 - 1e-12)))))


def estimate_error(scenario) -> ErrorEstimate:
    """Rerun ``scenario`` at its setting and at a tighter one and estimate the first's global error.

    Raises:
        TypeError: ``scenario`` is not a :class:`~coopctrl.scenario.Scenario`.
    """
    from coopctrl import wiring
    from coopctrl.analysis.tradeoff import run_errors, run_loop
    from coopctrl.errors import InfeasibleLoad
    from coopctrl.scenario import build

    wiring.check_scenario(scenario)
    sim = scenario.simulation
    cheap, tight, n, n2, setting, tighter, factor = _settings(sim)
    try:
        x0 = build.initial_state(scenario)
    except InfeasibleLoad as exc:
        return ErrorEstimate(None, None, None, setting, tighter, factor, 0.0, f"the loaded start failed: {exc}")
    if n2 == n and not sim.adaptive:
        return ErrorEstimate(None, None, None, setting, tighter, factor, 0.0,
                             f"no tighter step: substeps is already {MAX_SUBSTEPS}")
    run = run_loop(scenario, x0, cheap, n, sim.duration)
    if run.status != "ok":
        return ErrorEstimate(None, None, None, setting, tighter, factor, 0.0, f"the run {run.status}: {run.reason}")
    if sim.adaptive:
        return _against_reference(scenario, x0, run, setting)
    fine = run_loop(scenario, x0, tight, n2, sim.duration)
    if fine.status != "ok":
        return ErrorEstimate(None, None, None, setting, tighter, factor, fine.wall_time_s,
                             f"the tighter run {fine.status}: {fine.reason}")
    errors = run_errors(run, fine)
    values = [errors["position_error_m"] * factor, errors["orientation_error_rad"] * factor,
              errors["force_error_N"] * factor]
    if not all(math.isfinite(v) for v in values):
        return ErrorEstimate(None, None, None, setting, tighter, factor, fine.wall_time_s, "non-finite difference")
    return ErrorEstimate(*values, setting, tighter, factor, fine.wall_time_s)


def _against_reference(scenario, x0, run, setting: str) -> ErrorEstimate:
    """The bar of an error-controlled ``run``: its difference to RK4 at ``h_b`` plus RK4's own error there
    (module docstring)."""
    from coopctrl.analysis.tradeoff import run_errors, run_loop
    from coopctrl.integrators import get_integrator

    sim = scenario.simulation
    T = sim.control_period
    n_a = reference_substeps(run.record.get("integration_steps"), T)
    tighter = f"{REFERENCE_SCHEME} at h = T/{2 * n_a} = {T / (2 * n_a):.6g} s (and T/{n_a} for its own error)"
    coarse = run_loop(scenario, x0, get_integrator(REFERENCE_SCHEME), n_a, sim.duration)
    fine = run_loop(scenario, x0, get_integrator(REFERENCE_SCHEME), 2 * n_a, sim.duration)
    wall = coarse.wall_time_s + fine.wall_time_s
    for label, r in (("the reference", fine), ("the reference's check", coarse)):
        if r.status != "ok":
            return ErrorEstimate(None, None, None, setting, tighter, 1.0, wall, f"{label} {r.status}: {r.reason}")
    to_ref, own = run_errors(run, fine), run_errors(coarse, fine)
    share = 1.0 / (2.0 ** REFERENCE_ORDER - 1.0)
    values = [to_ref[k] + share * own[k] for k in ("position_error_m", "orientation_error_rad", "force_error_N")]
    if not all(math.isfinite(v) for v in values):
        return ErrorEstimate(None, None, None, setting, tighter, 1.0, wall, "non-finite difference")
    return ErrorEstimate(*values, setting, tighter, 1.0, wall)
