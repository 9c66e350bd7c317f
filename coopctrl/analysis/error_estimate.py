"""An error bar on a run: rerun at a tighter setting and compare (``coopctrl run --estimate-error``).

:func:`estimate_error` runs the scenario's closed loop twice from the same initial state: at its
own setting (the run being judged; bit for bit the run of ``coopctrl run``) and at a tighter one,

* fixed step ``h = T / n``: the same scheme at ``h / 2`` (``2 n`` substeps);
* error-controlled (``rk23``, ``rk45``, ``trbdf2``): ``rtol``, ``atol`` (and ``atol_velocity`` if
  set) 100 times smaller (``rtol`` floored at 1e-13),

and reports, each the maximum over the control instants ``t_k`` of the run, the difference of the
two runs in the object position ``|r_0 - r_0'|`` [m], orientation (angle of the relative rotation)
[rad] and contact forces ``max_i |f_i - f_i'|`` [N] (the same metrics as ``coopctrl tradeoff``).

Why the difference estimates the cheap run's error (Richardson's argument): the controller is
sampled at the same instants in both runs, so the two differ by their integration errors alone.
A fixed-step scheme of order ``p`` has a global error ``e(h) = C h^p + O(h^(p+1))``, so
``y_h - y_(h/2) = e(h) - e(h/2) = (1 - 2^-p) e(h)``: the estimate is the difference times
``2^p / (2^p - 1)`` (2 for Euler, 4/3 for the implicit midpoint rule, 16/15 for RK4). An
error-controlled scheme's global error is about proportional to its tolerance (tolerance
proportionality, which the step controller aims at): 100 times smaller tolerances leave 1 %
of the error, and the difference is ``0.99 e``; the estimate is the difference times 100 / 99.
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

from coopctrl.compact_repr import compact_repr

#: Tolerances of the tighter run of an error-controlled scheme: this many times smaller.
TOLERANCE_FACTOR = 100.0
#: Largest number of substeps of the tighter fixed-step run (the schema's ``simulation.substeps`` limit).
MAX_SUBSTEPS = 10000


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated global error of a run (see the module docstring).

    Attributes:
        position_m: Object position error [m]; orientation_rad: object orientation error [rad];
        force_N: contact force error [N]: each the maximum over the run of the difference of the two
            runs, times ``richardson_factor``. ``None`` when a run did not complete (``reason`` says).
        setting: The cheap run's setting; tighter_setting: the tighter run's (text).
        richardson_factor: ``2^p / (2^p - 1)`` (fixed step of order ``p``) or ``100 / 99``.
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
                f"(x{self.richardson_factor:.4g}, Richardson)"]


def _settings(sim) -> tuple[Any, Any, int, int, str, str, float]:
    """The cheap and tighter integrators, their substeps, their descriptions and the factor."""
    from coopctrl.integrators import get_integrator

    if sim.adaptive:
        def make(scale: float):
            return get_integrator(sim.integrator, rtol=max(1e-13, sim.rtol / scale), atol=sim.atol / scale,
                                  atol_velocity=None if sim.atol_velocity is None else sim.atol_velocity / scale,
                                  min_step=sim.min_step)

        cheap, tight = make(1.0), make(TOLERANCE_FACTOR)
        return (cheap, tight, 1, 1, f"{sim.integrator} at rtol {cheap.rtol:.3g}, atol {cheap.atol:.3g} m",
                f"{sim.integrator} at rtol {tight.rtol:.3g}, atol {tight.atol:.3g} m",
                TOLERANCE_FACTOR / (TOLERANCE_FACTOR - 1.0))
    cheap, tight = get_integrator(sim.integrator), get_integrator(sim.integrator)
    n = sim.substeps
    n2 = min(2 * n, MAX_SUBSTEPS)
    p = int(cheap.order)
    T = sim.control_period
    return (cheap, tight, n, n2, f"{sim.integrator} at h = T/{n} = {T / n:.6g} s",
            f"{sim.integrator} at h = T/{n2} = {T / n2:.6g} s", 2.0 ** p / (2.0 ** p - 1.0))


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
    fine = run_loop(scenario, x0, tight, n2, sim.duration)
    for label, r in (("the run", run), ("the tighter run", fine)):
        if r.status != "ok":
            return ErrorEstimate(None, None, None, setting, tighter, factor, fine.wall_time_s,
                                 f"{label} {r.status}: {r.reason}")
    errors = run_errors(run, fine)
    if sim.adaptive and run.rhs_evaluations == fine.rhs_evaluations and errors["position_error_m"] == 0.0:
        return ErrorEstimate(None, None, None, setting, tighter, factor, fine.wall_time_s,
                             "the tighter tolerances took the same steps (the control period, not the tolerance, "
                             "limits the step): rerun with a smaller rtol, or a fixed step")
    values = [errors["position_error_m"] * factor, errors["orientation_error_rad"] * factor,
              errors["force_error_N"] * factor]
    if not all(math.isfinite(v) for v in values):
        return ErrorEstimate(None, None, None, setting, tighter, factor, fine.wall_time_s, "non-finite difference")
    return ErrorEstimate(*values, setting, tighter, factor, fine.wall_time_s)
