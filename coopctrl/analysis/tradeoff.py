"""The speed-accuracy trade of the integrators: a grid of (integrator, setting) runs against a reference.

:func:`run_tradeoff` simulates a scenario's closed loop once with the reference solution
(:class:`~coopctrl.analysis.reference.ReferenceIntegrator`: ``solve_ivp`` over each control
period) and once per grid point, and reports for each run its error against the reference, its
wall time and real-time factor, and whether it is on the Pareto front of (wall time, error).
A grid point is a fixed-step scheme at a step ``h = T / n`` (``n`` substeps per control period),
or an error-controlled scheme (``rk23``, ``rk45``, ``trbdf2``) at a relative tolerance ``rtol``
with ``atol = ATOL_PER_RTOL * rtol`` [m] (the ratio of the defaults ``atol = 1e-8 m`` and
``rtol = 1e-6``; the velocities' ``atol / T``): its rows have ``rtol`` and ``atol`` and no step.

What is compared
----------------
Every run starts from the same state with a **new** closed loop
(:func:`coopctrl.wiring.closed_loop`): fresh follower PI integrators, a fresh QP warm start and
a sensor noise generator seeded with ``simulation.seed``. The controller is sampled at the same
instants ``t_k = k T`` in every run (the reference restarts its adaptive solver at each of them),
so the difference from the reference at ``t_k`` is the integration error alone, fed back through
the same controller. Two identical runs give identical output bit for bit
(``tests/test_tradeoff.py``). With sensor noise on, both runs draw the same noise sequence (same
seed, one draw per tick); the errors are still computed from the **true** states and forces.

Errors of a row, each the maximum over the control instants ``t_k`` of the run:

* ``position_error_m``: ``max_k |r_0(t_k) - r_0^ref(t_k)|``, the object MC position [m];
* ``orientation_error_rad``: ``max_k angle(R^ref(t_k)^T R(t_k))``, the angle [rad] of the
  relative rotation of the object (planar: the difference of ``theta``, wrapped to ``[-pi, pi]``);
* ``force_error_N``: ``max_k max_i |f_i(t_k) - f_i^ref(t_k)|``, the force part of the contact
  wrench of each interconnection (what a wrist sensor reads without noise) [N];
* ``force_error_relative``: ``force_error_N / max_k max_i |f_i^ref(t_k)|`` [-].

A run that diverges (or whose QP fails) keeps its status and reason, and its errors are ``None``;
the grid goes on. ``pareto`` marks the rows that no other row beats in both wall time and
position error; ``pareto_force`` the same with the force error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from fractions import Fraction
from pathlib import Path
from typing import Any, Callable, Sequence

import numpy as np

from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator
from coopctrl.compact_repr import compact_repr
from coopctrl.errors import CoopctrlError, ScenarioError
from coopctrl.integrators import ERROR_CONTROLLED, INTEGRATORS, get_integrator
from coopctrl.integrators.base import Integrator

#: Default grid: ``h = T / n`` for these ``n`` (substeps per control period).
DEFAULT_SUBSTEPS = (1, 2, 4, 8, 16)
#: Default relative tolerances [-] of the error-controlled schemes: 1e-3 to 1e-9 by decades.
DEFAULT_RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)
#: ``atol = ATOL_PER_RTOL * rtol`` [m] of a grid point (the defaults' ratio: 1e-8 m at rtol 1e-6).
ATOL_PER_RTOL = 1e-2
#: Largest number of substeps a step may ask for (``h >= T / MAX_SUBSTEPS``).
MAX_SUBSTEPS = 4096
#: Control periods of the untimed warm-up run before the reference (loads kernels, QP and scipy).
WARM_UP_TICKS = 10
#: Relative tolerance [-] on ``T / h`` being an integer (steps typed in decimal, e.g. 3.333e-4).
STEP_RTOL = 1e-6

#: Columns of a row, in the order of :meth:`TradeoffRow.to_dict`, the CSV file and the table.
ROW_FIELDS = ("integrator", "step_s", "substeps", "rtol", "atol", "position_error_m", "orientation_error_rad", "force_error_N",
              "force_error_relative", "wall_time_s", "realtime_factor", "rhs_evaluations", "status", "reason",
              "pareto", "pareto_force")


class ReferenceFailed(CoopctrlError, ArithmeticError):
    """The reference solution itself did not complete (it diverged, or the QP failed): there is
    nothing to measure errors against.

    Attributes:
        status: The reference run's status (``"diverged"`` or ``"qp_failed"``).
        reason: Its one-line reason.
    """

    def __init__(self, status: str, reason: str):
        self.status = status
        self.reason = reason
        super().__init__(f"the reference solution {status}: {reason}; there is nothing to measure the integrators "
                         "against (is the scene's closed loop stable at this control period?)")


# ---------------------------------------------------------------------- the grid
def allowed_steps(control_period: float, count: int = 8) -> list[float]:
    """The first ``count`` steps [s] that divide the control period: ``T / n``, ``n = 1, 2, ...``."""
    return [control_period / n for n in range(1, count + 1)]


def substeps_of(step: float, control_period: float, path: str = "--steps") -> int:
    """The number of substeps ``n = T / h`` of a step [s], which must divide ``T`` exactly.

    Raises:
        ScenarioError: naming the step and listing allowed ones, when ``T / h`` is not an integer
            (within :data:`STEP_RTOL`) in ``[1, MAX_SUBSTEPS]``.
    """
    T = float(control_period)
    h = float(step) if not isinstance(step, bool) else math.nan
    ratio = T / h if h > 0 and math.isfinite(h) else math.nan
    n = round(ratio) if math.isfinite(ratio) else 0
    if not (1 <= n <= MAX_SUBSTEPS and abs(ratio - n) <= STEP_RTOL * n):
        shown = ", ".join(f"{s:.6g}" for s in allowed_steps(T, 8))
        raise ScenarioError(path, step, f"a step h = T/n [s] that divides the control period T = {T:.6g} s "
                                        f"(n = 1..{MAX_SUBSTEPS}): {shown}, ... or written as T/n")
    return int(n)


def parse_steps(items: Sequence[str] | str, control_period: float) -> tuple[int, ...]:
    """Steps from the command line to substeps: each item is a step in [s] (``2.5e-4``) or ``T/n``
    (``T/4``); items may be comma-separated. Duplicates are dropped; order is by decreasing step.

    Raises:
        ScenarioError: for a malformed item or a step that does not divide the control period.
    """
    if isinstance(items, str):
        items = [items]
    out: set[int] = set()
    for item in items:
        for text in str(item).split(","):
            text = text.strip()
            if not text:
                continue
            if text.upper().startswith("T/"):
                try:
                    n = int(text[2:])
                except ValueError:
                    n = 0
                if not 1 <= n <= MAX_SUBSTEPS:
                    raise ScenarioError("--steps", text, f"T/n with an integer n in 1..{MAX_SUBSTEPS}")
                out.add(n)
                continue
            try:
                value = float(Fraction(text)) if "/" in text else float(text)
            except (ValueError, ZeroDivisionError):
                raise ScenarioError("--steps", text, "a step in seconds (2.5e-4) or T/n (T/4)") from None
            out.add(substeps_of(value, control_period))
    if not out:
        raise ScenarioError("--steps", ",".join(map(str, items)), "at least one step")
    return tuple(sorted(out))


def grid_integrators() -> tuple[str, ...]:
    """Every name the grid takes: the fixed-step schemes, then the error-controlled ones."""
    return (*INTEGRATORS, *ERROR_CONTROLLED)


def is_adaptive(name: str) -> bool:
    """Whether ``name`` is an error-controlled scheme (:data:`~coopctrl.integrators.ERROR_CONTROLLED`)."""
    return name in ERROR_CONTROLLED


def tolerances_of(rtol: float) -> dict[str, float]:
    """``{"rtol": rtol, "atol": ATOL_PER_RTOL * rtol}`` [-, m]: the tolerances of a grid point."""
    return {"rtol": float(rtol), "atol": ATOL_PER_RTOL * float(rtol)}


def make_integrator(name: str, rtol: float | None = None) -> Integrator:
    """A new integrator of the grid: ``name`` (fixed step), or an error-controlled ``name`` at
    ``rtol`` with ``atol = ATOL_PER_RTOL * rtol`` (:func:`tolerances_of`)."""
    if is_adaptive(name):
        return get_integrator(name, **tolerances_of(1e-6 if rtol is None else rtol))
    return get_integrator(name)


def parse_rtols(items: Sequence[str] | str) -> tuple[float, ...]:
    """Relative tolerances from the command line (comma-separated allowed), each in [1e-13, 0.1];
    duplicates dropped, loosest first.

    Raises:
        ScenarioError: for a malformed or out-of-range item.
    """
    if isinstance(items, str):
        items = [items]
    out: set[float] = set()
    for item in items:
        for text in str(item).split(","):
            text = text.strip()
            if not text:
                continue
            try:
                value = float(text)
            except ValueError:
                value = math.nan
            if not 1e-13 <= value <= 0.1:  # NaN fails
                raise ScenarioError("--rtols", text, "relative tolerances in [1e-13, 0.1] (e.g. 1e-4,1e-6)")
            out.add(value)
    if not out:
        raise ScenarioError("--rtols", ",".join(map(str, items)), "at least one tolerance")
    return tuple(sorted(out, reverse=True))


def parse_integrators(items: Sequence[str] | str | None) -> tuple[str, ...]:
    """Integrator names (comma-separated allowed), in the order given, checked against the registry
    (fixed-step and error-controlled schemes).

    Raises:
        ScenarioError: for an unknown name (the message lists the valid ones).
    """
    valid_names = grid_integrators()
    if items is None:
        return valid_names
    if isinstance(items, str):
        items = [items]
    names: list[str] = []
    for item in items:
        for name in str(item).split(","):
            name = name.strip()
            if not name:
                continue
            if name not in valid_names:
                valid = ", ".join(valid_names)
                raise ScenarioError("--integrators", name, f"names among {valid}")
            if name not in names:
                names.append(name)
    if not names:
        raise ScenarioError("--integrators", ",".join(items), f"at least one of {', '.join(valid_names)}")
    return tuple(names)


# ---------------------------------------------------------------------- one run
class _CountingIntegrator(Integrator):
    """Wraps an integrator to count right-hand-side calls (one Python call of overhead each).

    The counted ``f`` is built once per ``f`` and kept, so that a scheme caching on the identity of
    ``f`` (the Newton matrix of the implicit schemes) sees the same function at every step; a ``jac``
    of ``f`` or of its object is forwarded.
    """

    def __init__(self, inner: Integrator):
        self.inner = inner
        self.name = inner.name
        self.order = inner.order
        self.rhs_evaluations = 0
        self._f = None
        self._counted = None

    def _wrap(self, f):
        def counted(t, x, u):
            self.rhs_evaluations += 1
            return f(t, x, u)

        jac = getattr(f, "jac", None) or getattr(getattr(f, "__self__", None), "jac", None)
        if jac is not None:
            counted.jac = jac
        self._f, self._counted = f, counted
        return counted

    def step(self, f, t, x, u, h):
        counted = self._counted if (self._f is f) else self._wrap(f)
        return self.inner.step(counted, t, x, u, h)

    def predicted_max_step(self, omega_max: float, *args, **kwargs) -> float:
        return self.inner.predicted_max_step(omega_max, *args, **kwargs)

    @property
    def steps_taken(self):
        """The inner integrator's step count since its reset (the loop's step budget), or ``None``."""
        return getattr(self.inner, "steps_taken", None)

    def reset(self) -> None:
        self.inner.reset()


@dataclass(frozen=True, eq=False)
class LoopRun:
    """One closed-loop run of the grid (arrays at the control instants ``t_k``).

    Attributes:
        t: Control instants [s], (N,).
        Y0: Object pose ``Y_0`` [m, rad], (N, p).
        forces: True contact forces [N], (N, m, 2 or 3): the force part of each contact wrench.
        status: ``"ok"``, ``"diverged"`` or ``"qp_failed"``; reason: why, or ``""``.
        wall_time_s: Wall time of the loop [s]; rhs_evaluations: plant right-hand-side calls.
        record: The loop's full record (``ClosedLoop.run``).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    t: np.ndarray
    Y0: np.ndarray
    forces: np.ndarray
    status: str
    reason: str
    wall_time_s: float
    rhs_evaluations: int
    record: dict = field(repr=False)


def run_loop(scenario, x0, integrator: Integrator, substeps: int, duration: float | None = None) -> LoopRun:
    """Run a scenario's closed loop, built afresh, with ``integrator`` at ``h = T / substeps``.

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario`.
        x0: Initial state (:func:`coopctrl.scenario.build.initial_state`), the same for every run.
        integrator: A new :class:`~coopctrl.integrators.Integrator` (not shared between runs).
        substeps: Plant steps per control period, >= 1 (an error-controlled scheme ignores it).
        duration: Simulated time [s]; default ``simulation.duration``.
    """
    from coopctrl.analysis.diagnosis import diagnose_record
    from coopctrl.loop.build import compiled_unsupported
    from coopctrl.wiring import closed_loop

    step = scenario.simulation.control_period / int(substeps)
    loop = closed_loop(scenario, integrator=integrator, step=step)
    counted = None
    if compiled_unsupported(loop) is not None:  # the Python tick: count the calls through a wrapper
        counted = _CountingIntegrator(integrator)
        loop = closed_loop(scenario, integrator=counted, step=step)
    if not getattr(integrator, "adaptive", False) and loop.substeps != int(substeps):
        raise RuntimeError(f"the closed loop took {loop.substeps} substeps for T/{substeps}")
    duration = scenario.simulation.duration if duration is None else float(duration)
    rec = loop.run(np.asarray(x0, dtype=float), duration)
    diagnose_record(scenario, loop, rec)  # a failed run's causes, as simulate finds them
    plant = loop.plant
    p, nz, npos = plant.p, plant.nz, loop.npos
    x = rec["x"]
    if loop.sensors.forces.config.is_exact:
        F = rec["F_measured"]
    else:  # the record holds noisy readings: recompute the true forces from the states
        F = np.array([plant.control_terms(xk).Fw for xk in x]).reshape(len(x), plant.arm_count, p)
    return LoopRun(t=rec["t"], Y0=x[:, nz - p:nz].copy(), forces=np.array(F[:, :, :npos]), status=rec["status"],
                   reason=rec["reason"], wall_time_s=float(rec["wall_time_s"]),
                   rhs_evaluations=counted.rhs_evaluations if counted is not None else rec["rhs_evaluations"],
                   record=rec)


# ---------------------------------------------------------------------- errors
def orientation_angles(Y0: np.ndarray, Y0_ref: np.ndarray) -> np.ndarray:
    """Angle [rad] of the rotation from the reference to the actual object orientation, (N,).

    Planar: ``|theta - theta_ref|`` wrapped to ``[0, pi]``. Spatial: the magnitude of
    ``R(A_ref)^T R(A)`` with ``R = Rz(psi) Ry(theta) Rx(phi)`` (scipy's intrinsic ``"ZYX"``),
    computed through quaternions, so it is accurate for tiny angles (``arccos`` of the trace
    would bottom out near 1e-8 rad).
    """
    if Y0.shape[1] == 3:
        d = Y0[:, 2] - Y0_ref[:, 2]
        return np.abs((d + np.pi) % (2.0 * np.pi) - np.pi)
    from scipy.spatial.transform import Rotation

    R = Rotation.from_euler("ZYX", Y0[:, 3:6])
    R_ref = Rotation.from_euler("ZYX", Y0_ref[:, 3:6])
    return (R_ref.inv() * R).magnitude()


def measured_row(run: LoopRun, ref: LoopRun, name: str, control_period: float, substeps: int | None,
                 rtol: float | None) -> dict[str, Any]:
    """The fields of a :class:`TradeoffRow` (without the Pareto marks) of ``run`` against ``ref``:
    a fixed step ``T / substeps``, or an error-controlled scheme at ``rtol`` (``substeps`` ``None``)."""
    simulated = float(run.t[-1] - run.t[0]) if run.t.size > 1 else 0.0
    rtf = simulated / run.wall_time_s if run.wall_time_s > 0 and simulated > 0 else None
    errors = run_errors(run, ref) if run.status == "ok" else dict.fromkeys(
        ("position_error_m", "orientation_error_rad", "force_error_N", "force_error_relative"))
    tol = tolerances_of(rtol) if substeps is None else {"rtol": None, "atol": None}
    return dict(integrator=name, step_s=None if substeps is None else control_period / substeps, substeps=substeps,
                **tol, **errors, wall_time_s=run.wall_time_s, realtime_factor=rtf,
                rhs_evaluations=run.rhs_evaluations, status=run.status, reason=run.reason)


def mark_pareto(rows: list[dict]) -> None:
    """Set ``pareto`` and ``pareto_force`` of row dicts (see :func:`pareto_front`), in place."""
    walls = [r["wall_time_s"] for r in rows]
    for key, metric in (("pareto", "position_error_m"), ("pareto_force", "force_error_N")):
        for r, on in zip(rows, pareto_front(walls, [r[metric] for r in rows])):
            r[key] = on


def run_errors(run: LoopRun, ref: LoopRun) -> dict[str, float]:
    """The errors of a completed run against the reference (see the module docstring)."""
    if run.t.shape != ref.t.shape or not np.array_equal(run.t, ref.t):
        raise ValueError("run and reference are not sampled at the same control instants")
    npos = 2 if run.Y0.shape[1] == 3 else 3
    pos = np.linalg.norm(run.Y0[:, :npos] - ref.Y0[:, :npos], axis=1)
    ori = orientation_angles(run.Y0, ref.Y0)
    df = np.linalg.norm(run.forces - ref.forces, axis=-1)
    scale = float(np.max(np.linalg.norm(ref.forces, axis=-1))) if ref.forces.size else 0.0
    force = float(np.max(df)) if df.size else 0.0
    return {
        "position_error_m": float(np.max(pos)),
        "orientation_error_rad": float(np.max(ori)),
        "force_error_N": force,
        "force_error_relative": force / scale if scale > 0 else None,
    }


def pareto_front(costs: Sequence[float | None], errors: Sequence[float | None]) -> list[bool]:
    """Which points are not dominated: no other point has ``cost <=`` and ``error <=`` with one of
    them strictly smaller. Points with a missing (``None``) or non-finite value are never on it."""
    ok = [c is not None and e is not None and math.isfinite(c) and math.isfinite(e) for c, e in zip(costs, errors)]
    front = []
    for i, (ci, ei) in enumerate(zip(costs, errors)):
        if not ok[i]:
            front.append(False)
            continue
        dominated = any(ok[j] and j != i and costs[j] <= ci and errors[j] <= ei and (costs[j] < ci or errors[j] < ei)
                        for j in range(len(costs)))
        front.append(not dominated)
    return front


# ---------------------------------------------------------------------- results
@dataclass(frozen=True)
class TradeoffRow:
    """One grid point. Errors are ``None`` unless ``status == "ok"``; see the module docstring.

    Attributes:
        integrator: Registry name; step_s: ``h`` [s]; substeps: ``n = T / h`` (``None`` for an
            error-controlled scheme).
        rtol, atol: Tolerances [-, m] of an error-controlled scheme (``None`` for a fixed step).
        position_error_m, orientation_error_rad, force_error_N, force_error_relative: Errors
            against the reference (maximum over the run).
        wall_time_s: Wall time of the closed loop [s] (controller, QP and plant).
        realtime_factor: Simulated time / wall time [-] (of the part simulated, if it diverged).
        rhs_evaluations: Calls of the plant's right-hand side (Newton and finite-difference
            Jacobian calls included).
        status, reason: The run's status and, if not ok, why.
        pareto, pareto_force: On the Pareto front of (wall time, position error) or (wall time,
            force error).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    integrator: str
    step_s: float | None
    substeps: int | None
    rtol: float | None
    atol: float | None
    position_error_m: float | None
    orientation_error_rad: float | None
    force_error_N: float | None
    force_error_relative: float | None
    wall_time_s: float
    realtime_factor: float | None
    rhs_evaluations: int
    status: str
    reason: str
    pareto: bool = False
    pareto_force: bool = False

    def to_dict(self) -> dict[str, Any]:
        from coopctrl.results import json_safe

        return json_safe({name: getattr(self, name) for name in ROW_FIELDS})


@dataclass(frozen=True)
class ReferenceSummary:
    """How the reference was computed and what it cost.

    Attributes:
        config: The :class:`ReferenceConfig` (method, rtol, atol).
        wall_time_s: Its wall time [s]; rhs_evaluations: its right-hand-side calls.
        force_scale_N: ``max_k max_i |f_i^ref|`` [N], the scale of ``force_error_relative``.
        position_span_m: Largest distance [m] of the object MC from its start in the reference
            run (the motion the position errors are small against).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    config: ReferenceConfig
    wall_time_s: float
    rhs_evaluations: int
    force_scale_N: float
    position_span_m: float

    def to_dict(self) -> dict[str, Any]:
        from coopctrl.results import json_safe

        return json_safe({**self.config.to_dict(), "wall_time_s": self.wall_time_s,
                          "rhs_evaluations": self.rhs_evaluations, "force_scale_N": self.force_scale_N,
                          "position_span_m": self.position_span_m})


@dataclass(frozen=True)
class TradeoffResult:
    """The trade-off grid of one scenario.

    Attributes:
        scenario: Scenario name; duration_s: simulated time [s]; control_period_s: ``T`` [s].
        reference: The :class:`ReferenceSummary`; rows: one :class:`TradeoffRow` per grid point,
            by integrator then decreasing step.
        omega_max_rad_s: Highest mode [rad/s] of the plant linearized at the initial state
            (:meth:`ClosedLoop.omega_max`), for reading the steps against stability limits.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    scenario: str
    duration_s: float
    control_period_s: float
    reference: ReferenceSummary
    rows: tuple[TradeoffRow, ...]
    omega_max_rad_s: float | None = None

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON types only (no NaN: missing values are ``None``)."""
        from coopctrl.results import json_safe

        return json_safe({"scenario": self.scenario, "duration_s": self.duration_s,
                          "control_period_s": self.control_period_s, "omega_max_rad_s": self.omega_max_rad_s,
                          "reference": self.reference.to_dict(), "rows": [r.to_dict() for r in self.rows]})

    def row(self, integrator: str, setting: float) -> TradeoffRow:
        """The row of ``integrator`` at ``h = T / setting`` (fixed step: ``setting`` is the number of
        substeps) or at ``rtol = setting`` (error-controlled)."""
        key = "rtol" if is_adaptive(integrator) else "substeps"
        for r in self.rows:
            if r.integrator == integrator and getattr(r, key) == setting:
                return r
        shown = f"rtol {setting:g}" if key == "rtol" else f"T/{setting}"
        raise KeyError(f"no row ({integrator!r}, {shown}) in the grid")

    def table(self) -> str:
        """The grid as an aligned text table (``*`` marks the Pareto front: ``p`` position, ``f`` force)."""
        ref = self.reference
        c = ref.config
        head = [f"scenario {self.scenario}: {self.duration_s:.6g} s simulated, control period T = "
                f"{_duration(self.control_period_s)}"
                + (f", omega_max = {self.omega_max_rad_s:.4g} rad/s" if self.omega_max_rad_s else ""),
                f"reference: solve_ivp {c.method}, rtol {c.rtol:.3g}, atol {c.atol:.3g}, one call per control "
                f"period; wall time {ref.wall_time_s:.4g} s, {ref.rhs_evaluations} rhs evaluations"]
        cols = ["integrator", "step", "rtol", "pos err [m]", "ori err [rad]", "force err [N]", "force rel [-]",
                "wall [s]", "RTF [x]", "rhs evals", "status", "pareto"]
        lines = []
        for r in self.rows:
            front = ("p" if r.pareto else "") + ("f" if r.pareto_force else "")
            lines.append([r.integrator, setting_label(r), _num(r.rtol, "{:.0e}"), _num(r.position_error_m),
                          _num(r.orientation_error_rad), _num(r.force_error_N), _num(r.force_error_relative),
                          f"{r.wall_time_s:.3g}", _num(r.realtime_factor, "{:.3g}"), str(r.rhs_evaluations),
                          r.status, ("* " + front) if front else ""])
        widths = [max(len(cols[k]), *(len(line[k]) for line in lines)) if lines else len(cols[k])
                  for k in range(len(cols))]
        fmt = lambda parts: "  ".join(p.ljust(w) for p, w in zip(parts, widths)).rstrip()  # noqa: E731
        body = [fmt(cols)] + [fmt(line) for line in lines]
        notes = [f"{r.integrator} {setting_label(r)}: {r.reason}" for r in self.rows if r.status != "ok"]
        foot = ["pareto: * p = not beaten in both wall time and position error, f = in wall time and force error"]
        return "\n".join(head + [""] + body + [""] + foot + [f"  {n}" for n in notes])

    def save(self, directory: str | Path) -> list[Path]:
        """Write ``tradeoff.json``, ``tradeoff.csv`` and ``work_precision.png`` into ``directory``
        (created if missing), each atomically. Returns the paths."""
        import csv
        import io
        import json

        from coopctrl.analysis.work_precision_plot import plot_work_precision
        from coopctrl.io.atomic import atomic_write

        out = Path(directory)
        out.mkdir(parents=True, exist_ok=True)
        paths = [out / "tradeoff.json", out / "tradeoff.csv", out / "work_precision.png"]
        with atomic_write(paths[0]) as f:
            json.dump(self.to_dict(), f, indent=2, allow_nan=False)
            f.write("\n")
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(ROW_FIELDS)
        for r in self.rows:
            d = r.to_dict()
            writer.writerow(["" if d[k] is None else (repr(d[k]) if isinstance(d[k], float) else d[k])
                             for k in ROW_FIELDS])
        with atomic_write(paths[1]) as f:
            f.write(buffer.getvalue())
        plot_work_precision(self, paths[2])
        return paths


def setting_label(row) -> str:
    """``"250 us (T/4)"`` for a fixed step, ``"adaptive"`` for an error-controlled row (its ``rtol``
    is in its own column)."""
    if row.substeps is None:
        return "adaptive"
    return f"{_duration(row.step_s)} (T/{row.substeps})"


def _timed(run: Callable[[], LoopRun], repeats: int) -> LoopRun:
    """The first of ``repeats`` identical runs, with the smallest wall time of them."""
    first = run()
    best = first.wall_time_s
    for _ in range(int(repeats) - 1):
        best = min(best, run().wall_time_s)
    return replace(first, wall_time_s=best)


def _duration(seconds: float) -> str:
    for scale, unit in ((1.0, "s"), (1e-3, "ms"), (1e-6, "us")):
        if seconds >= scale:
            return f"{seconds / scale:.4g} {unit}"
    return f"{seconds:.3g} s"


def _num(value, fmt: str = "{:.3e}") -> str:
    return "-" if value is None else fmt.format(value)


# ---------------------------------------------------------------------- the driver
def run_tradeoff(scenario, integrators: Sequence[str] | None = None, substeps: Sequence[int] | None = None,
                 reference: ReferenceConfig | None = None, repeats: int = 1,
                 progress: Callable[[str], None] | None = None, rtols: Sequence[float] | None = None,
                 duration: float | None = None) -> TradeoffResult:
    """Run the reference, then every (integrator, step or tolerance) of the grid, and compare.

    Args:
        scenario: The :class:`~coopctrl.scenario.Scenario` (its ``simulation.duration`` is the
            simulated time: shorten it with an override, ``simulation.duration = 0.3``).
        integrators: Registry names; default: all of :data:`~coopctrl.integrators.INTEGRATORS`
            then all of :data:`~coopctrl.integrators.ERROR_CONTROLLED`.
        substeps: ``n`` of the steps ``h = T / n`` of the fixed-step schemes; default
            :data:`DEFAULT_SUBSTEPS`. Use :func:`parse_steps` or :func:`substeps_of` to turn steps
            in seconds into these.
        reference: The :class:`ReferenceConfig` (default DOP853, rtol 1e-11, atol 1e-12).
        repeats: Runs per grid point (and of the reference), >= 1; the wall time reported is the
            smallest (the least disturbed by other load on the machine). The runs are identical
            bit for bit, so the errors do not depend on it.
        progress: Called with a short label before each run (e.g. to print progress).
        rtols: Relative tolerances of the error-controlled schemes, each in [1e-13, 0.1];
            default :data:`DEFAULT_RTOLS` (``atol = ATOL_PER_RTOL * rtol``).
        duration: Simulated time [s] (rounded to whole control periods); default
            ``simulation.duration``.

    Returns:
        The :class:`TradeoffResult`.

    Raises:
        ReferenceFailed: when the reference run does not complete.
        ScenarioError: for an unknown integrator or a bad number of substeps.
    """
    from coopctrl.errors import InfeasibleLoad
    from coopctrl.scenario import build
    from coopctrl.wiring import closed_loop
    from plants.errors import PlantError

    names = parse_integrators(list(integrators) if integrators is not None else None)
    grid = tuple(DEFAULT_SUBSTEPS if substeps is None else substeps)
    for n in grid:
        if isinstance(n, bool) or int(n) != n or not 1 <= n <= MAX_SUBSTEPS:
            raise ScenarioError("substeps", n, f"an integer in 1..{MAX_SUBSTEPS}")
    grid = tuple(sorted({int(n) for n in grid}))
    if isinstance(repeats, bool) or int(repeats) != repeats or repeats < 1:
        raise ScenarioError("repeats", repeats, "an integer >= 1")
    tolerances = DEFAULT_RTOLS if rtols is None else tuple(rtols)
    for rtol in tolerances:
        if isinstance(rtol, bool) or not isinstance(rtol, (int, float)) or not 1e-13 <= rtol <= 0.1:
            raise ScenarioError("rtols", rtol, "relative tolerances in [1e-13, 0.1]")
    tolerances = tuple(sorted({float(r) for r in tolerances}, reverse=True))
    config = reference if reference is not None else ReferenceConfig()
    sim = scenario.simulation
    T = sim.control_period
    try:
        x0 = build.initial_state(scenario)
    except InfeasibleLoad as exc:
        raise ReferenceFailed("qp_failed", f"at t = 0 s (loaded start): {exc}") from None
    if duration is None:
        duration = sim.control_steps * T
    elif isinstance(duration, bool) or not isinstance(duration, (int, float)) or not T <= duration <= sim.duration:
        raise ScenarioError("duration", duration, f"a time in [{T:g}, {sim.duration:g}] s (one control period "
                                                  "to simulation.duration)")
    else:
        duration = max(1, round(duration / T)) * T
    # warm-up, untimed: first calls of the kernels, the QP and scipy must not be charged to a row
    run_loop(scenario, x0, get_integrator("rk4"), 1, min(duration, WARM_UP_TICKS * T))
    if progress:
        progress(f"reference ({config.method})")
    ref = _timed(lambda: run_loop(scenario, x0, ReferenceIntegrator(config), 1, duration), repeats)
    if ref.status != "ok":
        raise ReferenceFailed(ref.status, ref.reason)
    npos = 2 if ref.Y0.shape[1] == 3 else 3
    span = float(np.max(np.linalg.norm(ref.Y0[:, :npos] - ref.Y0[0, :npos], axis=1)))
    force_scale = float(np.max(np.linalg.norm(ref.forces, axis=-1))) if ref.forces.size else 0.0
    rows = []
    for name in names:
        settings = [(None, rtol) for rtol in tolerances] if is_adaptive(name) else [(n, None) for n in grid]
        for n, rtol in settings:
            if progress:
                progress(f"{name} rtol {rtol:g}" if n is None else f"{name} T/{n}")
            run = _timed(lambda: run_loop(scenario, x0, make_integrator(name, rtol), n or 1, duration), repeats)
            rows.append(measured_row(run, ref, name, T, n, rtol))
    mark_pareto(rows)
    try:
        omega = closed_loop(scenario).omega_max(x0)
    except (PlantError, ArithmeticError, ValueError):  # a diagnostic only: it must not lose the grid
        omega = None
    return TradeoffResult(scenario=scenario.name, duration_s=duration, control_period_s=T,
                          reference=ReferenceSummary(config, ref.wall_time_s, ref.rhs_evaluations, force_scale, span),
                          rows=tuple(TradeoffRow(**r) for r in rows), omega_max_rad_s=omega)
