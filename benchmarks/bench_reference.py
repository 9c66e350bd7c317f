"""The compiled closed loop against scipy's solve_ivp at equal accuracy (error <= 1e-6).

Run from the repository root::

    python benchmarks/bench_reference.py [--repeats 5] [--quick] [--tolerance 1e-6] [--sections 1,2,3,4]

Sections 3 and 4 (issue 19) measure the error-controlled schemes of the compiled loop:

3. **rk45 against solve_ivp's RK45** on the closed loop of section 1: the compiled ``rk45`` at the
   loosest ``rtol = atol`` (decades; atol on positions and velocities alike) whose run reaches the
   tolerance, and solve_ivp's RK45 restarted at every tick at the same rtol and atol (the same
   restarts at the control instants, the last step carried as ``first_step``): whole-loop medians,
   errors, right-hand-side evaluations and rejected-step rates side by side (rk23 against RK23 too).
   Target: >= 20x.
4. **trbdf2 on stiff_grasp_extreme** (1e7 N/m grasps): its contact-force error at rtol 1e-5 (max over
   the ticks against solve_ivp DOP853 at rtol 1e-10 per tick), and for every fixed-step scheme the
   fewest substeps reaching that error (doubling, then bisection); whole-loop medians round-robin.
   Target: trbdf2 faster than every fixed step.

Two settings, both on spatial_two_puma_carry (two Pumas, 36 states), in one run:

1. **The closed loop the user runs** (``coopctrl.simulator.closed_loop(scenario).run``, as
   ``coopctrl.simulate`` runs it): 0.5 s of the carry, the controller at T = 1 ms with the torque held
   between ticks. A fixed-step integrator takes ``n`` substeps of ``h = T / n`` per tick; euler,
   symplectic_euler, rk4 and the implicit schemes run in the compiled loop (the whole tick in one
   compiled core); a scheme the core does not implement steps the plant in Python between core
   calls (its rows say "plant in Python"). The reference is the same
   loop, same scenario, same controller code and the same compiled QP, with the plant integrated by
   solve_ivp, restarted at every tick over ``[t_k, t_k + T]`` (the held torque jumps there; the last
   accepted step is passed on as ``first_step``): the same kernel runs the tick and stops at each
   period for solve_ivp, a Python call, to step the plant.
   The error of a run is the largest deviation, over all ticks, of the positions z = (q, Y_0)
   [rad, m] from a reference run whose ticks are integrated by DOP853 at rtol = atol = 1e-12 with at
   most T/4 per step (checked against RK4 at T/64, an independent method; the difference is printed).
   Two times per run, both medians over ``--repeats`` runs taken round-robin in the same process:
   - **whole loop**: the wall time of ``loop.run(x0, 0.5)`` (sensors, QP, controllers, integration,
     guards, recording; a warm-up run first loads the compiled kernel, a one-time cost per process);
   - **integration only**: solve_ivp's calls (timed around each call); for the
     compiled loop, the same zero-order-hold integration replayed by the core's schemes on the run's
     recorded torques with the plant's allocation-free right-hand side (the kernel's arithmetic: the
     replayed states are checked to equal the run's, and the difference is printed).
   The ratios solve_ivp / fixed step are printed for both, and the verdict against issue 10's target:
   the fastest fixed-step closed loop at least 50 times faster, whole loop, than the fastest solve_ivp
   loop. When it is not reached, the time per tick of both sides is broken down (integration,
   right-hand-side evaluations, the rest of the tick), with what 50x would need.
2. **The plant alone over one horizon** (the most favourable case for an adaptive solver: one
   call, a smooth right-hand side): from the loaded initial state, with the constant joint
   torques that hold the arms still, the object is struck (0.1 m/s along each axis, 0.5 rad/s
   about each Euler axis), so the grasp springs ring (omega_max ~ 440 rad/s), over 0.2 s; the
   error is at the final time, against DOP853 at rtol = atol = 1e-13. Both sides step from Python
   (the fixed-step schemes of ``coopctrl.integrators``). Target: 10x.

For each method the cheapest setting that reaches error <= tolerance: fixed step (euler,
symplectic_euler, rk4, implicit_midpoint, implicit_euler) the largest step T / n (n doubled, then
bisected to 5 %); solve_ivp (RK45, DOP853, Radau, LSODA) the loosest rtol of 1e-1, 1e-2, ..., 1e-12 with
atol = rtol (the states are O(0.1 to 1) in [rad], [m], [rad/s], [m/s]): the reference gets its best
setting too.
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

import coopctrl  # noqa: E402
from coopctrl.integrators import Integrator, get_integrator  # noqa: E402
from coopctrl.simulator import closed_loop  # noqa: E402
from coopctrl.loop.build import compiled_unsupported  # noqa: E402

SCENE = REPO / "scenarios" / "spatial_two_puma_carry.toml"
FIXED = ("euler", "symplectic_euler", "rk4", "implicit_midpoint", "implicit_euler")
IVP = ("RK45", "DOP853", "Radau", "LSODA")
RTOLS = tuple(10.0 ** -k for k in range(1, 13))
#: Right-hand-side evaluations per step of the explicit schemes (the implicit ones vary).
EVALS_PER_STEP = {"euler": 1, "symplectic_euler": 1, "rk4": 4}
#: Speed-up target of the plant alone: fastest solve_ivp time / fastest fixed-step time.
TARGET = 10.0

LOOP_DURATION = 0.5  # s of the carry in the closed-loop setting
LOOP_N_MAX = 64  # most substeps per tick tried (first-order schemes need more; they are reported as not reaching)
HORIZON = 0.2  # s, open-loop setting
KICK = np.array([0.1, 0.1, 0.1, 0.5, 0.5, 0.5])  # initial object velocity [m/s, rad/s]
OPEN_N_MAX = 8 * 2 ** 17


class IvpStep(Integrator):
    """One plant step = one ``solve_ivp`` call over ``[t, t + h]`` with ``u`` held (the last
    accepted step is the next call's ``first_step``)."""

    def __init__(self, method: str, rtol: float, atol: float | None = None, max_step: float = math.inf):
        self.name, self.method, self.rtol = method, method, rtol
        self.atol = rtol if atol is None else atol
        self.max_step = max_step
        self.nfev = 0
        self.accepted = 0
        self.calls = 0
        self._last = None

    def predicted_max_step(self, omega_max):
        return math.inf

    def reset(self):
        """A fresh start: no step carried over, no evaluations counted."""
        self.nfev, self.accepted, self.calls, self._last = 0, 0, 0, None

    def step(self, f, t, x, u, h):
        first = None if self._last is None else min(self._last, (t + h) - t)
        with np.errstate(all="ignore"):
            sol = solve_ivp(lambda s, y: f(s, y, u), (t, t + h), x, method=self.method, rtol=self.rtol,
                            atol=self.atol, first_step=first, max_step=self.max_step)
        self.nfev += sol.nfev
        self.calls += 1
        self.accepted += max(0, sol.t.size - 1)
        if sol.status != 0 or not sol.y.shape[1]:
            return np.full_like(x, np.nan)
        if sol.t.size >= 2:
            self._last = float(np.max(np.diff(sol.t)))
        return sol.y[:, -1].copy()


class Timed(Integrator):
    """Wraps an integrator and adds up the wall time of its steps [s]."""

    def __init__(self, inner):
        self.inner, self.name, self.seconds = inner, inner.name, 0.0

    def predicted_max_step(self, omega_max):
        return self.inner.predicted_max_step(omega_max)

    def step(self, f, t, x, u, h):
        t0 = time.perf_counter()
        out = self.inner.step(f, t, x, u, h)
        self.seconds += time.perf_counter() - t0
        return out


#: Issue 10: the fastest fixed-step closed loop against the fastest solve_ivp loop, whole loop [-].
TARGET_LOOP = 50.0


def error(x, ref, nz):
    """Largest position deviation [rad, m]: ``x`` and ``ref`` are states or (N, nx) runs."""
    x, ref = np.atleast_2d(x), np.atleast_2d(ref)
    if x.shape != ref.shape:
        return math.inf  # a run that stopped early (diverged)
    e = float(np.max(np.abs(x[:, :nz] - ref[:, :nz])))
    return e if math.isfinite(e) else math.inf


# ---------------------------------------------------------------------- 1. closed loop
#: The fixed-step schemes whose integration the benchmark replays on a run's recorded torques.
REPLAY_METHODS = ("euler", "symplectic_euler", "rk4")


class LoopRun:
    """One chosen setting of the closed loop: its loop object (built once, run again and again, as the
    public API allows) and its timings."""

    def __init__(self, problem, kind: str, name: str, setting):
        self.problem, self.kind, self.name, self.setting = problem, kind, name, setting
        s = problem.scenario_with(setting if kind == "fixed" else 1)
        if kind == "fixed":
            self.integrator = get_integrator(name)
        else:
            self.integrator = IvpStep(name, setting)
        self.compiled = compiled_unsupported(closed_loop(s, integrator=self.integrator)) is None
        self.timed = None if self.compiled else Timed(self.integrator)
        self.loop = closed_loop(s, integrator=self.integrator if self.compiled else self.timed)
        self.whole, self.integ, self.evals, self.replay_diff = [], [], 0, math.nan

    def run(self):
        """One timed run: ``(rec, whole seconds)``; the integration time is added to :attr:`integ`."""
        if isinstance(self.integrator, IvpStep):
            self.integrator.reset()
        if self.timed is not None:
            self.timed.seconds = 0.0
        t0 = time.perf_counter()
        with np.errstate(all="ignore"):
            rec = self.loop.run(self.problem.x0, LOOP_DURATION)
        whole = time.perf_counter() - t0
        if self.compiled and self.name in REPLAY_METHODS:
            seconds, self.evals, self.replay_diff = self.problem.replay(self.loop, rec)
        elif self.compiled:  # a scheme compiled in the kernel that the replay does not implement: not split out
            seconds, self.evals = math.nan, rec.get("rhs_evaluations", 0)
        else:
            seconds = self.timed.seconds
            self.evals = getattr(self.integrator, "nfev", 0) or EVALS_PER_STEP.get(self.name, 0) * self.setting * (len(rec["t"]) - 1)
        self.whole.append(whole)
        self.integ.append(seconds)
        return rec, whole

    @property
    def label(self) -> str:
        return self.name + (" (compiled)" if self.compiled else " (plant in Python)")


class LoopProblem:
    def __init__(self):
        self.scenario = coopctrl.load_scenario(SCENE, {"simulation.duration": str(LOOP_DURATION)})
        self.x0 = self.scenario.initial_state()
        self.plant = self.scenario.plant()
        self.nz = self.plant.nz

    def scenario_with(self, substeps: int):
        if substeps == 1:
            return self.scenario
        return coopctrl.load_scenario(SCENE, {"simulation.duration": str(LOOP_DURATION),
                                              "simulation.substeps": str(substeps)})

    def run(self, integrator, substeps: int = 1):
        """``(x (N, nx), integration seconds, loop seconds, rhs evaluations)`` of one run (the search)."""
        loop = closed_loop(self.scenario_with(substeps), integrator=integrator)
        with np.errstate(all="ignore"):
            rec = loop.run(self.x0, LOOP_DURATION)
        x = rec["x"] if rec["status"] == "ok" else np.full((1, len(self.x0)), np.nan)
        return x, math.nan, rec["wall_time_s"], getattr(integrator, "nfev", 0)

    def fixed(self, name, n):
        return self.run(get_integrator(name), n)

    def ivp(self, method, rtol, atol=None, max_step=math.inf):
        return self.run(IvpStep(method, rtol, atol, max_step))

    def replay(self, loop, rec):
        """``(seconds, rhs evaluations, max |replayed - recorded| state)`` of the compiled loop's integration
        replayed on the recorded torques of ``rec``: each tick's torques held over the period's steps by the core's
        scheme (``coopctrl._core.plant_advance``, one call a tick: its call from Python included)."""
        import coopctrl._core as _core
        from coopctrl.integrators.compiled import make_plan

        taus = np.ascontiguousarray(rec["tau"])
        nx = self.x0.size
        xs = np.empty((taus.shape[0], nx))
        steps = np.array(loop._steps, dtype=float)
        plan = make_plan(loop.integrator, nx, loop.T)
        status, x_fail, report = np.zeros(2, np.int64), np.zeros(nx), _core.StopReport()
        P = self.plant.plant_args
        x = np.array(self.x0, dtype=float)
        xs[0] = x
        t0 = time.perf_counter()
        for k in range(taus.shape[0] - 1):
            _core.plant_advance(plan, x, taus[k], P, status, k * loop.T, steps, x_fail, report)
            xs[k + 1] = x
        seconds = time.perf_counter() - t0
        return seconds, report.rhs_evaluations, float(np.max(np.abs(xs - rec["x"]))) if xs.shape == rec["x"].shape else math.inf


def python_rhs_seconds(plant, x, tau, calls: int = 2000) -> float:
    """Median [s] of one ``plant.rhs`` call from Python (the right-hand side solve_ivp calls)."""
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        for _ in range(calls):
            plant.rhs(0.0, x, tau)
        times.append((time.perf_counter() - t0) / calls)
    return statistics.median(times)


def compare_loop(problem, ref, tol, fixed, ivp, repeats):
    """The closed loop (module docstring, 1.): cheapest settings, timed round-robin; table, ratios, verdict,
    and the breakdown per tick when the target is missed."""
    t0 = time.perf_counter()
    chosen = []  # (kind, name, setting, error)
    for name in fixed:
        n, e = cheapest_n(problem, name, ref, tol, 1, LOOP_N_MAX)
        if n is None:
            print(f"  {name}: error {e:.2e} > {tol:g} even at n = {LOOP_N_MAX}; not timed")
        else:
            chosen.append(("fixed", name, n, e))
    for method in ivp:
        rtol, e = loosest_rtol(problem, method, ref, tol)
        if rtol is None:
            print(f"  {method}: error {e:.2e} > {tol:g} at every rtol down to {RTOLS[-1]:g}; not timed")
        else:
            chosen.append(("ivp", method, rtol, e))
    print(f"  (search for the cheapest settings: {time.perf_counter() - t0:.1f} s)")
    runs = [LoopRun(problem, kind, name, setting) for kind, name, setting, _ in chosen]
    for r in runs:  # warm-up: loads the compiled kernels (once per process), then every run is timed
        r.run()
        r.whole.clear()
        r.integ.clear()
    for _ in range(repeats):
        for r in runs:
            rec, _ = r.run()
            if rec["status"] != "ok":
                raise SystemExit(f"{r.label} stopped: {rec['reason']}")
    ticks = len(ref) - 1
    whole = [statistics.median(r.whole) for r in runs]
    integ = [statistics.median(r.integ) for r in runs]
    fixed_rows = [k for k, c in enumerate(chosen) if c[0] == "fixed"]
    ivp_rows = [k for k, c in enumerate(chosen) if c[0] == "ivp"]
    if not fixed_rows or not ivp_rows:
        print("  target not evaluated (closed loop): no fixed-step or no solve_ivp method reached the tolerance")
        return None, None
    bf = min(fixed_rows, key=lambda k: whole[k])
    bi = min(ivp_rows, key=lambda k: whole[k])
    bf_i = min((k for k in fixed_rows if not math.isnan(integ[k])), key=lambda k: integ[k], default=bf)
    bi_i = min(ivp_rows, key=lambda k: integ[k])
    print(f"\n{'method':30s} {'setting':>22s} {'error':>8s} {'rhs evals':>9s} {'whole loop':>11s} {'us/tick':>8s} "
          f"{'integration':>12s} {'us/tick':>8s}")
    for k, (kind, name, setting, e) in enumerate(chosen):
        text = f"h = T/{setting} = {problem.step_of(setting) * 1e3:.3g} ms" if kind == "fixed" else f"rtol = atol = {setting:g}"
        print(f"{runs[k].label:30s} {text:>22s} {e:8.1e} {runs[k].evals or '-':>9} {whole[k] * 1e3:8.2f} ms "
              f"{whole[k] / ticks * 1e6:8.1f} {integ[k] * 1e3:9.2f} ms {integ[k] / ticks * 1e6:8.1f}")
    replayed = [k for k in fixed_rows if runs[k].compiled and runs[k].name in REPLAY_METHODS]
    if replayed:
        print("  compiled integration replayed on the recorded torques; max |replayed - recorded state|: "
              + ", ".join(f"{runs[k].name} {runs[k].replay_diff:.1e}" for k in replayed))
    print(f"\n  solve_ivp loop / fixed-step loop, whole loop (integration only), at error <= {tol:g}:")
    print("  " + f"{'':10s}" + "".join(f"{runs[k].label:>32s}" for k in fixed_rows))
    for j in ivp_rows:
        print("  " + f"{runs[j].name:10s}" + "".join(f"{whole[j] / whole[k]:>20.1f}x ({integ[j] / integ[k]:6.1f}x)"
                                                     for k in fixed_rows))
    ratio = whole[bi] / whole[bf]
    ratio_i = integ[bi_i] / integ[bf_i]
    verdict = "PASS" if ratio >= TARGET_LOOP else "FAIL"
    print(f"\n  target (closed loop, issue 10): the fastest fixed-step loop ({runs[bf].label}) >= {TARGET_LOOP:g}x faster "
          f"than the fastest solve_ivp loop ({runs[bi].name}), whole loop: {ratio:.1f}x  {verdict}")
    print(f"  integration only: fastest fixed step ({runs[bf_i].label}) {ratio_i:.1f}x faster than the fastest "
          f"solve_ivp ({runs[bi_i].name})")
    if verdict == "FAIL":
        profile_loop(problem, runs[bf], runs[bi], whole[bf], integ[bf], whole[bi], integ[bi], ticks)
    return ratio, ratio_i


def profile_loop(problem, fixed_run, ivp_run, w_f, i_f, w_i, i_i, ticks):
    """Where the time per tick goes on both sides of the missed target, and what 50x would need."""
    x = np.ascontiguousarray(problem.x0, dtype=float)
    tau = np.zeros(problem.plant.input_size)
    rhs_py = python_rhs_seconds(problem.plant, x, tau)
    us = 1e6 / ticks
    print(f"\n  profile per tick (us, medians; {ticks} ticks):")
    ev_f = fixed_run.evals / ticks
    rhs_f = i_f / fixed_run.evals if fixed_run.evals else math.nan
    print(f"    {fixed_run.label:28s} whole {w_f * us:8.1f} = integration {i_f * us:7.1f} ({ev_f:.0f} rhs x "
          f"{rhs_f * 1e6:.2f} us) + the rest of the tick {(w_f - i_f) * us:7.1f} (sensors, nominal motion, QP, "
          "controllers, guards, recording)")
    ev_i = ivp_run.evals / ticks
    print(f"    {ivp_run.label:28s} whole {w_i * us:8.1f} = solve_ivp {i_i * us:7.1f} ({ev_i:.1f} rhs x {rhs_py * 1e6:.1f} "
          f"us from Python = {ev_i * rhs_py * 1e6:.0f}, solver {(i_i / ticks - ev_i * rhs_py) * 1e6:.0f}) + the rest of the "
          f"tick {(w_i - i_i) * us:7.1f}")
    print(f"    {TARGET_LOOP:g}x needs the fixed-step loop at <= {w_i * us / TARGET_LOOP:.1f} us per tick "
          f"({w_f * us / (w_i * us / TARGET_LOOP):.1f}x faster than now); its integration alone takes {i_f * us:.1f}")


# ---------------------------------------------------------------------- 2. plant alone
class OpenProblem:
    def __init__(self):
        s = coopctrl.load_scenario(SCENE)
        plant = s.plant()
        x0 = np.array(s.initial_state(), dtype=float)
        nz, nq = plant.nz, plant.input_size
        # holding torque: Gamma z'' + phi = (tau, 0) at rest, so tau = phi_q = -N ddq(tau = 0)
        ddz0 = plant.rhs(0.0, x0, np.zeros(nq))[nz:]
        tau = -plant.mass_matrix(x0)[:nq, :nq] @ ddz0[:nq]
        assert np.max(np.abs(plant.rhs(0.0, x0, tau)[nz:nz + nq])) < 1e-9, "the holding torque does not hold the arms"
        x0[nz + nz - 6:] = KICK
        self.plant, self.x0, self.tau, self.nz = plant, np.ascontiguousarray(x0), tau, nz

    def fixed(self, name, n):
        scheme = get_integrator(name)
        h = HORIZON / n
        x = self.x0.copy()
        step, rhs, tau = scheme.step, self.plant.rhs, self.tau
        t0 = time.perf_counter()
        with np.errstate(all="ignore"):
            for k in range(n):
                x = step(rhs, k * h, x, tau, h)
        seconds = time.perf_counter() - t0
        return x, seconds, seconds, EVALS_PER_STEP.get(name, 0) * n

    def ivp(self, method, rtol, atol=None):
        rhs, tau = self.plant.rhs, self.tau
        t0 = time.perf_counter()
        with np.errstate(all="ignore"):
            sol = solve_ivp(lambda t, x: rhs(t, x, tau), (0.0, HORIZON), self.x0, method=method, rtol=rtol,
                            atol=rtol if atol is None else atol)
        seconds = time.perf_counter() - t0
        x = sol.y[:, -1] if sol.success else np.full_like(self.x0, np.nan)
        return x, seconds, seconds, sol.nfev


# ---------------------------------------------------------------------- search and timing
def _error_of(problem, kind, name, setting, ref):
    try:
        x = (problem.fixed(name, setting) if kind == "fixed" else problem.ivp(name, setting))[0]
    except ArithmeticError:  # e.g. Newton failure of the implicit scheme at a large step
        return math.inf
    return error(x, ref, problem.nz)


def cheapest_n(problem, name, ref, tol, n_start, n_max):
    """Smallest n (to 5 %) with error <= tol: ``(n, error)``, or ``(None, last error)``."""
    n, fail = n_start, None
    while True:
        e = _error_of(problem, "fixed", name, n, ref)
        if e <= tol:
            break
        fail, n = n, 2 * n
        if n > n_max:
            return None, e
    ok, err_ok = n, e
    lo = fail if fail is not None else n_start - 1
    while ok - lo > max(1, 0.05 * ok):
        mid = (lo + ok) // 2
        e = _error_of(problem, "fixed", name, mid, ref)
        if e <= tol:
            ok, err_ok = mid, e
        else:
            lo = mid
    return ok, err_ok


def loosest_rtol(problem, method, ref, tol):
    e = math.inf
    for rtol in RTOLS:
        e = _error_of(problem, "ivp", method, rtol, ref)
        if e <= tol:
            return rtol, e
    return None, e


def compare(title, problem, ref, tol, fixed, ivp, n_start, n_max, step_unit, repeats):
    """Find the cheapest settings, time them round-robin, print the table and the verdict."""
    t0 = time.perf_counter()
    chosen = []  # (kind, name, setting, error)
    for name in fixed:
        n, e = cheapest_n(problem, name, ref, tol, n_start, n_max)
        if n is None:
            print(f"  {name}: error {e:.2e} > {tol:g} even at n = {n_max}; not timed")
        else:
            chosen.append(("fixed", name, n, e))
    for method in ivp:
        rtol, e = loosest_rtol(problem, method, ref, tol)
        if rtol is None:
            print(f"  {method}: error {e:.2e} > {tol:g} at every rtol down to {RTOLS[-1]:g}; not timed")
        else:
            chosen.append(("ivp", method, rtol, e))
    print(f"  (search for the cheapest settings: {time.perf_counter() - t0:.1f} s)")
    integ = [[] for _ in chosen]
    whole = [[] for _ in chosen]
    evals = [0] * len(chosen)
    for _ in range(repeats):
        for k, (kind, name, setting, _) in enumerate(chosen):
            _, seconds, total, evals[k] = problem.fixed(name, setting) if kind == "fixed" else problem.ivp(name, setting)
            integ[k].append(seconds)
            whole[k].append(total)
    med = [statistics.median(v) for v in integ]
    med_whole = [statistics.median(v) for v in whole]
    fixed_rows = [k for k, c in enumerate(chosen) if c[0] == "fixed"]
    ivp_rows = [k for k, c in enumerate(chosen) if c[0] == "ivp"]
    best_fixed = min(fixed_rows, key=lambda k: med[k]) if fixed_rows else None
    best_ivp = min(ivp_rows, key=lambda k: med[k]) if ivp_rows else None
    show_whole = med_whole != med
    print(f"\n{'method':18s} {'setting':>28s} {'error':>9s} {'rhs evals':>10s} {'integration':>12s} "
          f"{'vs fastest fixed':>17s}" + (f" {'whole loop':>11s} {'vs fastest fixed':>17s}" if show_whole else ""))
    for k, (kind, name, setting, e) in enumerate(chosen):
        text = f"h = {step_unit}/{setting} = {problem.step_of(setting) * 1e3:.3g} ms" if kind == "fixed" \
            else f"rtol = atol = {setting:g}"
        line = (f"{name:18s} {text:>28s} {e:9.1e} {evals[k] or '-':>10} {med[k] * 1e3:9.2f} ms "
                f"{med[k] / med[best_fixed]:16.1f}x")
        if show_whole:
            line += f" {med_whole[k] * 1e3:8.1f} ms {med_whole[k] / med_whole[best_fixed]:16.1f}x"
        print(line)
    if best_fixed is None or best_ivp is None:
        print(f"  target not evaluated ({title}): no fixed-step or no solve_ivp method reached the tolerance")
        return None
    print(f"\n  solve_ivp / fixed step, integration time, at error <= {tol:g}:")
    print("  " + f"{'':16s}" + "".join(f"{chosen[k][1]:>19s}" for k in fixed_rows))
    for j in ivp_rows:
        print("  " + f"{chosen[j][1]:16s}" + "".join(f"{med[j] / med[k]:18.1f}x" for k in fixed_rows))
    speedup = med[best_ivp] / med[best_fixed]
    verdict = "PASS" if speedup >= TARGET else "FAIL"
    print(f"\n  target ({title}): fastest fixed step ({chosen[best_fixed][1]}) >= {TARGET:g}x faster than the fastest "
          f"solve_ivp ({chosen[best_ivp][1]}): {speedup:.1f}x  {verdict}")
    if show_whole:
        best_fixed_whole = min(fixed_rows, key=lambda k: med_whole[k])
        best_ivp_whole = min(ivp_rows, key=lambda k: med_whole[k])
        whole = med_whole[best_ivp_whole] / med_whole[best_fixed_whole]
        print(f"  whole loop ({title}): fastest fixed step ({chosen[best_fixed_whole][1]}, the compiled tick) "
              f"{whole:.1f}x faster than the fastest solve_ivp loop ({chosen[best_ivp_whole][1]}); issue 10 target >= "
              f"{TARGET_LOOP:g}x  {'PASS' if whole >= TARGET_LOOP else 'FAIL'}")
    return speedup


#: Issue 19: the compiled rk45 closed loop against solve_ivp's RK45 at the same rtol/atol, whole loop [-].
TARGET_ADAPTIVE = 20.0
#: The stiff scene of section 4 and its force reference.
STIFF_SCENE = REPO / "scenarios" / "stiff_grasp_extreme.toml"
#: Tolerances tried for the error-controlled schemes (atol = rtol [m, rad] and [m/s, rad/s]).
ADAPTIVE_RTOLS = tuple(10.0 ** -k for k in range(2, 12))
#: Fixed-step schemes of section 4, and their most substeps per period.
STIFF_FIXED = ("symplectic_euler", "rk4", "implicit_midpoint", "implicit_euler")
STIFF_N_MAX = 64


def _median_wall(loop, x0, duration, repeats, before=None):
    """Median wall time [s] of ``repeats`` runs of ``loop`` after one warm-up (``before()`` resets
    what a run accumulates), and the last record."""
    times = []
    rec = None
    for _ in range(repeats + 1):
        if before is not None:
            before()
        t0 = time.perf_counter()
        with np.errstate(all="ignore"):
            rec = loop.run(x0, duration)
        times.append(time.perf_counter() - t0)
    return statistics.median(times[1:]), rec


def _rejected_share(rec) -> float:
    s = rec.integration_steps
    acc, rej = float(s[:, 0].sum()), float(s[:, 1].sum())
    return rej / (acc + rej) if acc + rej else 0.0


def compare_adaptive(problem, ref, tol, repeats):
    """Section 3: the compiled rk45 (and rk23) closed loop against solve_ivp's RK45 (RK23) restarted at
    every tick, at the same rtol and atol; the loosest rtol at which the compiled scheme reaches ``tol``."""
    T = problem.scenario.simulation.control_period
    rows = []
    for name, method in (("rk45", "RK45"), ("rk23", "RK23")):
        chosen = None
        for rtol in ADAPTIVE_RTOLS:
            sc = coopctrl.load_scenario(SCENE, {"simulation.duration": str(LOOP_DURATION), "simulation.integrator": name,
                                                "simulation.rtol": repr(rtol), "simulation.atol": repr(rtol),
                                                "simulation.atol_velocity": repr(rtol)})
            loop = closed_loop(sc)
            with np.errstate(all="ignore"):
                rec = loop.run(problem.x0, LOOP_DURATION)
            e = error(rec["x"], ref, problem.nz) if rec["status"] == "ok" else math.inf
            if e <= tol:
                chosen = (rtol, loop, e)
                break
        if chosen is None:
            print(f"  {name}: error > {tol:g} at every rtol down to {ADAPTIVE_RTOLS[-1]:g}")
            continue
        rtol, loop, e = chosen
        ivp = IvpStep(method, rtol, rtol)
        ivp_loop = closed_loop(problem.scenario, integrator=ivp)
        w_c, rec_c = _median_wall(loop, problem.x0, LOOP_DURATION, repeats)
        w_i, rec_i = _median_wall(ivp_loop, problem.x0, LOOP_DURATION, max(1, repeats // 2), before=ivp.reset)
        e_i = error(rec_i["x"], ref, problem.nz) if rec_i["status"] == "ok" else math.inf
        attempted = (ivp.nfev - ivp.calls) / (6 if method == "RK45" else 3)  # first_step given: f(t0), then s per try
        rej_i = max(0.0, attempted - ivp.accepted) / attempted if attempted else 0.0
        rows.append((name, method, rtol, e, e_i, w_c, w_i, rec_c, rej_i, ivp))
    ticks = len(ref) - 1
    print(f"\n{'scheme':22s} {'rtol = atol':>11s} {'error':>8s} {'rhs evals':>9s} {'rejected':>9s} {'whole loop':>11s} "
          f"{'us/tick':>8s}")
    for name, method, rtol, e, e_i, w_c, w_i, rec_c, rej_i, ivp in rows:
        print(f"{name + ' (compiled)':22s} {rtol:11.0e} {e:8.1e} {rec_c.rhs_evaluations:9d} {_rejected_share(rec_c):8.2%} "
              f"{w_c * 1e3:8.2f} ms {w_c / ticks * 1e6:8.1f}")
        print(f"{'solve_ivp ' + method:22s} {rtol:11.0e} {e_i:8.1e} {ivp.nfev:9d} {rej_i:8.2%} {w_i * 1e3:8.2f} ms "
              f"{w_i / ticks * 1e6:8.1f}")
    result = None
    for name, method, rtol, e, e_i, w_c, w_i, *_ in rows:
        ratio = w_i / w_c
        verdict = "PASS" if ratio >= TARGET_ADAPTIVE else "FAIL"
        print(f"  compiled {name} vs solve_ivp {method} at rtol = atol = {rtol:.0e} (error <= {tol:g}), whole loop: "
              f"{ratio:.1f}x faster" + (f"  (target >= {TARGET_ADAPTIVE:g}x: {verdict})" if name == "rk45" else ""))
        if name == "rk45":
            result = ratio
    return result


def compare_stiff(repeats):
    """Section 4: stiff_grasp_extreme, TR-BDF2 against every fixed step reaching its contact-force error."""
    sc = coopctrl.load_scenario(STIFF_SCENE)
    x0 = sc.initial_state()
    ivp = IvpStep("DOP853", 1e-10, 1e-12)
    with np.errstate(all="ignore"):
        ref = closed_loop(sc, integrator=ivp).run(x0, sc.simulation.duration)
    F_ref = ref["F_measured"]

    def run(overrides):
        loop = closed_loop(coopctrl.load_scenario(STIFF_SCENE, overrides))
        with np.errstate(all="ignore"):
            rec = loop.run(x0, sc.simulation.duration)
        ok = rec["status"] == "ok"
        return loop, rec, (float(np.max(np.abs(rec["F_measured"] - F_ref))) if ok else math.inf)

    tr = {"simulation.integrator": "trbdf2", "simulation.rtol": "1e-5", "simulation.atol": "1e-7"}
    loop_t, rec_t, e_t = run(tr)
    chosen = [("trbdf2 rtol 1e-5", loop_t, rec_t, e_t)]
    for name in STIFF_FIXED:
        n, fail, found = 1, 0, None
        while n <= STIFF_N_MAX:
            loop, rec, e = run({"simulation.integrator": name, "simulation.substeps": str(n)})
            if e <= e_t:
                found = (n, loop, rec, e)
                break
            fail, n = n, 2 * n
        if found is None:
            print(f"  {name}: contact-force error > {e_t:.3g} N even at T/{STIFF_N_MAX}; not timed")
            continue
        lo = fail
        while found[0] - lo > 1:
            mid = (lo + found[0]) // 2
            loop, rec, e = run({"simulation.integrator": name, "simulation.substeps": str(mid)})
            if e <= e_t:
                found = (mid, loop, rec, e)
            else:
                lo = mid
        chosen.append((f"{name} T/{found[0]}", found[1], found[2], found[3]))
    walls = [[] for _ in chosen]
    for _ in range(repeats + 1):  # round-robin, the first round a warm-up
        for k, (_, loop, _, _) in enumerate(chosen):
            t0 = time.perf_counter()
            with np.errstate(all="ignore"):
                loop.run(x0, sc.simulation.duration)
            walls[k].append(time.perf_counter() - t0)
    med = [statistics.median(w[1:]) for w in walls]
    print(f"\n{'setting':26s} {'force error':>11s} {'rhs evals':>9s} {'rejected':>9s} {'whole loop':>11s}")
    for (label, _, rec, e), w in zip(chosen, med):
        rej = f"{_rejected_share(rec):8.2%}" if rec.integration_steps is not None else "-"
        print(f"{label:26s} {e:9.3g} N {rec.rhs_evaluations:9d} {rej:>9s} {w * 1e3:8.2f} ms")
    fastest_fixed = min(med[1:]) if len(med) > 1 else math.inf
    verdict = "PASS" if med[0] < fastest_fixed else "FAIL"
    print(f"  trbdf2 faster than every fixed step reaching its contact-force error ({e_t:.3g} N): "
          f"{fastest_fixed / med[0]:.2f}x the fastest  {verdict}")
    return fastest_fixed / med[0]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per chosen setting (default 5)")
    parser.add_argument("--quick", action="store_true", help="no explicit or implicit "
                        "Euler and no Radau (the slowest searches: first order needs up to 3e5 steps for 1e-6)")
    parser.add_argument("--tolerance", type=float, default=1e-6, help="error to reach [rad, m] (default 1e-6)")
    parser.add_argument("--sections", default="1,2,3,4", help="sections to run (default 1,2,3,4; 3 and 4: the "
                        "error-controlled schemes)")
    args = parser.parse_args(argv)
    sections = {int(k) for k in args.sections.split(",")}
    repeats = args.repeats
    fixed = tuple(n for n in FIXED if not (args.quick and n in ("euler", "implicit_euler")))
    ivp = tuple(m for m in IVP if not (args.quick and m == "Radau"))
    tol = args.tolerance
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"machine: {platform.machine()} python {platform.python_version()} numpy {np.__version__}, "
          f"{os.cpu_count()} cpus (load average {os.getloadavg()[0]:.1f}); medians of {repeats} timed run(s); tolerance {tol:g} [rad, m] on the positions")
    t_start = time.perf_counter()

    loop = LoopProblem()
    T = loop.scenario.simulation.control_period
    loop.step_of = lambda n: T / n
    # the closed loop is smooth enough that DOP853 takes one 1 ms step per tick even at rtol 1e-12: force
    # four steps per tick, and check the reference against an independent method (RK4 at T / 64)
    ref = loop.ivp("DOP853", 1e-12, max_step=T / 4)[0]
    ref_err = error(ref, loop.fixed("rk4", 64)[0], loop.nz)
    print(f"\n1. closed loop: spatial_two_puma_carry, {LOOP_DURATION} s at T = {T * 1e3:g} ms (error: max over the "
          f"{len(ref)} ticks); reference DOP853 per tick at rtol 1e-12 with at least 4 steps per tick, its "
          f"difference from RK4 at T/64: {ref_err:.1e}")
    loop_speedup = loop_integration = adaptive_speedup = stiff_speedup = open_speedup = None
    if 1 in sections:
        loop_speedup, loop_integration = compare_loop(loop, ref, tol, fixed, ivp, repeats)
    if 3 in sections:
        print(f"\n3. error-controlled, closed loop: spatial_two_puma_carry as in 1.; the compiled rk45 and rk23 at the "
              f"loosest rtol = atol (decades) reaching {tol:g}, against solve_ivp's RK45 and RK23 restarted at every "
              "tick at the same rtol and atol (the last step carried as first_step)")
        adaptive_speedup = compare_adaptive(loop, ref, tol, repeats)
    if 4 in sections:
        print("\n4. error-controlled, stiff: stiff_grasp_extreme (1e7 N/m grasps, omega_max ~ 5000 rad/s, 1 s), contact "
              "forces against solve_ivp DOP853 per tick at rtol 1e-10; trbdf2 at rtol 1e-5 against each fixed step's "
              "fewest substeps reaching the same force error")
        stiff_speedup = compare_stiff(repeats)

    if 2 in sections:
        open_ = OpenProblem()
        open_.step_of = lambda n: HORIZON / n
        ref = open_.ivp("DOP853", 1e-13)[0]
        ref_err = error(ref, open_.ivp("DOP853", 3e-14)[0], open_.nz)
        print(f"\n2. plant alone over {HORIZON} s, holding torque, object struck (error at the final time); reference "
              f"DOP853 at rtol 1e-13, its error estimate {ref_err:.1e}")
        open_speedup = compare("plant alone", open_, ref, tol, fixed, ivp, 8, OPEN_N_MAX, "0.2 s", repeats)

    fmt = (lambda v: "-" if v is None else f"{v:.1f}x")
    print(f"\nsummary (total {time.perf_counter() - t_start:.0f} s): at error <= {tol:g}, the fastest fixed-step closed "
          f"loop is {fmt(loop_speedup)} faster than the fastest solve_ivp loop, whole loop (target >= {TARGET_LOOP:g}x), "
          f"{fmt(loop_integration)} integration only; plant alone {fmt(open_speedup)} (target >= {TARGET:g}x); compiled "
          f"rk45 {fmt(adaptive_speedup)} faster than solve_ivp RK45 at the same tolerances (target >= {TARGET_ADAPTIVE:g}x); "
          f"trbdf2 {fmt(stiff_speedup)} the fastest fixed step at its force error on the stiff scene (target > 1x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
