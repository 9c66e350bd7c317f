"""End to end per shipped scene: the ticks alone, ``simulate()``, the CLI run, pre-flight and a sweep.

Run: python benchmarks/bench_end_to_end.py [--repeats N] [--sweep-runs N] [--jobs N] [--scenes a,b] [--quick]
     python benchmarks/bench_end_to_end.py --profile spatial_two_puma_carry
     python benchmarks/bench_end_to_end.py --profile-sweep spatial_two_puma_carry

For every shipped scene (``scenarios/*.toml``), after a warm-up of each measure (never timed), ``repeats`` rounds each time, side by side in that order:

* **ticks**: the compiled tick alone, the sum of the wall times of the calls into ``Tick.run_ticks`` of a
  ``closed_loop(scenario).run(x0, duration)`` (``loop.run``, timed too: the loop's per-run set-up on
  top of the ticks; the approach of ``bench_closed_loop.py``). The calls are timed by wrapping the tick
  class the loop builds once per run (``coopctrl.loop.run._core.Tick``: there is no public hook for the
  ticks' time). Where that hook is missing the ticks column is ``loop.run`` and the output says so;
* **simulate**: ``coopctrl.simulate(scenario)`` in this process (the scenario loaded once);
* **CLI**: ``coopctrl.cli.main(["run", SCENE, "-q"])`` in this process: loading the scene file, the
  record's memory check, pre-flight, the run and its summary; no output folder;
* **RT**: the real-time factor ``coopctrl run`` prints, from ``main(["run", SCENE, "--json"])``;
* **pre-flight**: ``coopctrl.analysis.preflight.preflight(scenario, loop)`` alone, as ``coopctrl run`` calls
  it: on the closed loop it then runs (built once for both; its build is timed with the run).

Then one ``coopctrl sweep SCENE --grid simulation.seed=0,...,N-1 --jobs J --json`` (``--sweep-runs N``,
default 200; ``--jobs J``, default 2), in this process as the CLI, timed from its call to its return
(the workers' start-up included, as a user waits for it): carries per minute ``= 60 N / wall``. A scene
whose run is not ok (it diverges, or pre-flight refuses it) is not swept: its carries would be failures.

Beside the wall times, the process CPU time of the ticks, ``simulate()``, the CLI run and pre-flight (and of
the sweep with its workers, per run): on a shared machine the wall time grows with the load, the CPU time
much less. Medians over the repeats are printed per scene with the ratios simulate/ticks and CLI/ticks, and for
``spatial_two_puma_carry`` the targets of issue 18 with a verdict each. ``--profile SCENE`` instead
prints the top 25 cumulative entries of cProfile over one in-process ``coopctrl run SCENE -q`` (after a
warm-up run), so that a missed target comes with its profile; ``--profile-sweep SCENE`` the same over an
in-process sweep of 40 runs with ``--jobs 1`` (a worker's per-run cost).
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import io
import json
import os
import platform
import pstats
import resource
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
SCENES = sorted(p.stem for p in (REPO / "scenarios").glob("*.toml"))
#: The scene the targets are stated for.
CARRY = "spatial_two_puma_carry"
#: Targets of issue 18 on :data:`CARRY`.
TARGET_RT = 75.0  # coopctrl run's printed real-time factor, at least [x]
TARGET_SIMULATE = 1.2  # simulate() / ticks, at most
TARGET_CLI = 1.5  # in-process CLI run / ticks, at most
TARGET_PREFLIGHT_S = 0.010  # pre-flight alone, at most [s]
TARGET_CARRIES_PER_MIN = 2500.0  # sweep with --jobs 2, at least
TARGET_TICK_S = 12e-6  # one tick, at most [s]


class KernelClock:
    """The summed wall time [s] of the calls into the compiled tick since :meth:`reset`.

    Installed by wrapping the tick class the loop builds once per run (``coopctrl._core.Tick``, as
    ``coopctrl.loop.run`` reaches it): each call of its ``run_ticks`` (a chunk of ticks) and
    ``reference_step`` (a tick of the reference path) is timed, about 1 us of its own each.
    """

    def __init__(self):
        self.total = 0.0
        self.cpu = 0.0  # the same calls' process CPU time [s]
        self.installed = self._install()

    def _install(self) -> bool:
        try:
            import coopctrl.loop.run as loop_run

            core = loop_run._core
            Tick = core.Tick
        except (ImportError, AttributeError):
            return False
        clock = self

        class TimedTick:
            def __init__(self, *args):
                self._tick = Tick(*args)

            def _timed(self, method, *a):
                t0, c0 = time.perf_counter(), time.process_time()
                try:
                    return method(*a)
                finally:
                    clock.total += time.perf_counter() - t0
                    clock.cpu += time.process_time() - c0

            def run_ticks(self, *a):
                return self._timed(self._tick.run_ticks, *a)

            def reference_step(self, *a):
                return self._timed(self._tick.reference_step, *a)

            def __getattr__(self, name):
                return getattr(self._tick, name)

        class Core:  # the compiled module with its Tick timed
            def __getattr__(self, name):
                return TimedTick if name == "Tick" else getattr(core, name)

        loop_run._core = Core()
        return True

    def reset(self) -> None:
        self.total = 0.0
        self.cpu = 0.0


@contextlib.contextmanager
def _quiet():
    """stdout and stderr of an in-process CLI call captured (returned as two StringIO)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        yield out, err


def _cpu_with_children() -> float:
    """CPU time [s] of this process and of its ended children (a sweep's workers once it stopped them)."""
    me, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + children.ru_utime + children.ru_stime


#: CPU time [s] of the last :func:`_cli` call (this process and the children it ended).
_last_cpu = [0.0]


def _cli(argv: list[str]) -> tuple[float, int, str, str]:
    """``(wall [s], exit code, stdout, stderr)`` of ``coopctrl.cli.main(argv)`` in this process (its CPU time
    in ``_last_cpu[0]``)."""
    from coopctrl.cli import main

    with _quiet() as (out, err):
        c0 = _cpu_with_children()
        t0 = time.perf_counter()
        code = main(argv)
        wall = time.perf_counter() - t0
        _last_cpu[0] = _cpu_with_children() - c0
    if code in (130, 143):  # the CLI handled Ctrl-C or SIGTERM and returned: the benchmark stops too
        raise SystemExit(code)
    return wall, code, out.getvalue(), err.getvalue()


def _last_line(text: str) -> str:
    lines = [s for s in text.strip().splitlines() if s.strip()]
    return lines[-1] if lines else ""


def measure_scene(name: str, repeats: int, sweep_runs: int, jobs: int, clock: KernelClock) -> dict:
    """Medians of every measure of scene ``name`` (see the module docstring)."""
    import coopctrl
    from coopctrl.analysis.preflight import preflight
    from coopctrl.scenario import build
    from coopctrl.simulator import closed_loop

    path = str(REPO / "scenarios" / f"{name}.toml")
    scenario = coopctrl.load_scenario(path)
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    duration = scenario.simulation.duration
    # warm-up: every measure once (numba compiles or loads its kernels here)
    rec = loop.run(x0, duration)
    coopctrl.simulate(scenario)
    _cli(["run", path, "-q"])
    preflight(scenario, loop)
    ticks = len(rec["t"])
    series = {k: [] for k in ("ticks", "loop_run", "simulate", "cli", "cli_json", "preflight", "rt",
                              "ticks_cpu", "simulate_cpu", "cli_cpu", "preflight_cpu")}
    cli_code, cli_err, status = 0, "", rec["status"]
    for _ in range(repeats):
        clock.reset()
        t0 = time.perf_counter()
        rec = loop.run(x0, duration)
        wall = time.perf_counter() - t0
        series["loop_run"].append(wall)
        series["ticks"].append(clock.total if clock.installed else wall)
        series["ticks_cpu"].append(clock.cpu if clock.installed else float("nan"))
        c0, t0 = time.process_time(), time.perf_counter()
        coopctrl.simulate(scenario)
        series["simulate"].append(time.perf_counter() - t0)
        series["simulate_cpu"].append(time.process_time() - c0)
        wall, cli_code, _, cli_err = _cli(["run", path, "-q"])
        series["cli"].append(wall)
        series["cli_cpu"].append(_last_cpu[0])
        wall, _, out, _ = _cli(["run", path, "--json"])
        series["cli_json"].append(wall)
        try:
            rt = json.loads(out).get("realtime_factor")
        except ValueError:  # pre-flight refused the task: no summary
            rt = None
        series["rt"].append(float("nan") if rt is None else float(rt))
        c0, t0 = time.process_time(), time.perf_counter()
        preflight(scenario, loop)
        series["preflight"].append(time.perf_counter() - t0)
        series["preflight_cpu"].append(time.process_time() - c0)
    med = {k: statistics.median(v) for k, v in series.items()}
    sweep = None
    if sweep_runs > 0 and status != "ok":  # its carries would be failures (a diverging run also costs its diagnosis)
        sweep = {"skipped": f"skipped: the scene's run is {status}"}
    elif sweep_runs > 0:
        seeds = ",".join(str(s) for s in range(sweep_runs))
        wall, code, out, err = _cli(["sweep", path, "--grid", f"simulation.seed={seeds}", "--jobs", str(jobs), "--json"])
        rows = json.loads(out)["rows"] if code == 0 else []
        failed = sum(1 for r in rows if r.get("status") != "ok")
        sweep = {"runs": sweep_runs, "wall": wall, "per_min": 60.0 * sweep_runs / wall, "failed": failed,
                 "code": code, "error": _last_line(err) if code else "", "cpu": _last_cpu[0]}
    simulated = max(ticks - 1, 1) * scenario.simulation.control_period
    return {"name": name, "status": status, "ticks_n": ticks, "simulated": simulated, "med": med, "sweep": sweep,
            "cli_code": cli_code, "cli_err": _last_line(cli_err), "repeats": repeats}


def _ms(seconds: float) -> str:
    return f"{seconds * 1e3:9.2f} ms"


def _verdict(ok: bool) -> str:
    return "met" if ok else "MISSED"


def print_scene(r: dict, clock_installed: bool, jobs: int) -> None:
    """One scene's table: medians, ratios to the ticks, and the targets on :data:`CARRY`."""
    med, n = r["med"], r["ticks_n"]
    carry = r["name"] == CARRY
    ticks = med["ticks"]
    tick_label = "ticks (compiled kernel)" if clock_installed else "ticks (= loop.run: no kernel clock)"
    cli_note = "" if r["cli_code"] == 0 else f"  (exit {r['cli_code']}: {r['cli_err']})"
    print(f"\n== {r['name']}: status {r['status']}, {n} ticks, {r['simulated']:.4g} s simulated, "
          f"medians of {r['repeats']}{cli_note}")
    print(f"{'measure':36s} {'median':>12s} {'/ ticks':>8s}   {'target (issue 18)':22s} verdict")

    def row(label, value, ratio="", target="", verdict=""):
        print(f"{label:36s} {value:>12s} {ratio:>8s}   {target:22s} {verdict}")

    tick_us = ticks / n * 1e6
    row(tick_label, _ms(ticks), "1.00x", "tick <= 12 us" if carry else "",
        f"{_verdict(ticks / n <= TARGET_TICK_S)} ({tick_us:.1f} us/tick)" if carry else f"({tick_us:.1f} us/tick)")
    row("loop.run (per-run set-up + ticks)", _ms(med["loop_run"]), f"{med['loop_run'] / ticks:.2f}x")
    s = med["simulate"] / ticks
    row("simulate()", _ms(med["simulate"]), f"{s:.2f}x", "<= 1.2x ticks" if carry else "",
        _verdict(s <= TARGET_SIMULATE) if carry else "")
    c = med["cli"] / ticks
    row("CLI run -q (pre-flight included)", _ms(med["cli"]), f"{c:.2f}x", "<= 1.5x ticks" if carry else "",
        _verdict(c <= TARGET_CLI) if carry else "")
    row("CLI run --json", _ms(med["cli_json"]), f"{med['cli_json'] / ticks:.2f}x")
    row("pre-flight alone", _ms(med["preflight"]), f"{med['preflight'] / ticks:.2f}x", "<= 10 ms" if carry else "",
        _verdict(med["preflight"] <= TARGET_PREFLIGHT_S) if carry else "")
    rt = med["rt"]
    row("real-time factor coopctrl run prints", "-" if rt != rt else f"{rt:10.1f} x", "", ">= 75x" if carry else "",
        (_verdict(rt >= TARGET_RT) if rt == rt else "MISSED (no summary)") if carry else "")
    row("real-time factor of the ticks alone", f"{r['simulated'] / ticks:10.1f} x")
    tc = med["ticks_cpu"]
    if tc == tc and tc > 0:  # CPU time: what a quiet machine's wall time would be (the load inflates the wall)
        row("CPU: ticks", _ms(tc), "1.00x")
        row("CPU: simulate()", _ms(med["simulate_cpu"]), f"{med['simulate_cpu'] / tc:.2f}x")
        row("CPU: CLI run -q", _ms(med["cli_cpu"]), f"{med['cli_cpu'] / tc:.2f}x")
        row("CPU: pre-flight alone", _ms(med["preflight_cpu"]), f"{med['preflight_cpu'] / tc:.2f}x")
    sw = r["sweep"]
    if sw is not None:
        if "skipped" in sw:
            row(f"sweep --jobs {jobs}", "-", "", "", sw["skipped"])
        elif sw["code"] != 0:
            row(f"sweep of {sw['runs']} runs --jobs {jobs}", f"exit {sw['code']}", "", "", sw["error"])
        else:
            note = f"; {sw['failed']} of {sw['runs']} runs not ok" if sw["failed"] else ""
            row(f"sweep of {sw['runs']} runs --jobs {jobs}", f"{sw['wall']:10.2f} s")
            row("  CPU per run (sweep and workers)", _ms(sw["cpu"] / sw["runs"]),
                f"{sw['cpu'] / sw['runs'] / tc:.2f}x" if tc == tc and tc > 0 else "")
            row("  carries a minute", f"{sw['per_min']:12.0f}", "", ">= 2500 a minute" if carry else "",
                (_verdict(sw["per_min"] >= TARGET_CARRIES_PER_MIN) + note) if carry else note.lstrip("; "))


def print_overview(results: list[dict]) -> None:
    """One line per scene: the medians and the two ratios."""
    print(f"\n{'scene':28s} {'status':8s} {'ticks':>5s} {'us/tick':>7s} {'ticks ms':>8s} {'sim ms':>8s} {'CLI ms':>8s} "
          f"{'pre ms':>7s} {'sim/t':>6s} {'CLI/t':>6s} {'RT':>6s} {'carries/min':>11s} {'CPU sim/t':>9s} {'CPU CLI/t':>9s}")
    for r in results:
        med, n, ticks = r["med"], r["ticks_n"], r["med"]["ticks"]
        sw = r["sweep"]
        per_min = "-" if sw is None or sw.get("code", 1) else f"{sw['per_min']:.0f}"
        rt = "-" if med["rt"] != med["rt"] else f"{med['rt']:.1f}"
        print(f"{r['name']:28s} {r['status']:8s} {n:5d} {ticks / n * 1e6:7.1f} {ticks * 1e3:8.1f} "
              f"{med['simulate'] * 1e3:8.1f} {med['cli'] * 1e3:8.1f} {med['preflight'] * 1e3:7.1f} "
              f"{med['simulate'] / ticks:5.2f}x {med['cli'] / ticks:5.2f}x {rt:>6s} {per_min:>11s} "
              f"{med['simulate_cpu'] / med['ticks_cpu']:8.2f}x {med['cli_cpu'] / med['ticks_cpu']:8.2f}x", flush=True)


def profile_cli(name: str, top: int = 25) -> None:
    """cProfile of one in-process ``coopctrl run NAME -q`` after a warm-up run: the top cumulative entries."""
    from coopctrl.cli import main

    path = str(REPO / "scenarios" / f"{name}.toml")
    _cli(["run", path, "-q"])  # warm-up: compile or load the kernels
    profiler = cProfile.Profile()
    with _quiet():
        t0 = time.perf_counter()
        code = profiler.runcall(main, ["run", path, "-q"])
        wall = time.perf_counter() - t0
    print(f"profile of `coopctrl run {name} -q` in process (exit {code}, {wall * 1e3:.1f} ms under the profiler); "
          f"top {top} by cumulative time:")
    stats = pstats.Stats(profiler, stream=sys.stdout)
    stats.sort_stats("cumulative").print_stats(top)


def profile_sweep(name: str, runs: int = 40, top: int = 25) -> None:
    """cProfile of one in-process ``coopctrl sweep NAME --grid simulation.seed=0,...,runs-1 --jobs 1`` after a
    warm-up sweep of 2 runs: with ``--jobs 1`` the runs execute in this process, each as a worker runs it
    (:func:`coopctrl.sweep.worker.execute_run`), so the profile shows a worker's per-run cost (without the
    process pool's pickling, about 0.4 ms a run)."""
    from coopctrl.cli import main

    path = str(REPO / "scenarios" / f"{name}.toml")
    _cli(["sweep", path, "--grid", "simulation.seed=0,1", "--jobs", "1", "--json"])  # warm-up: kernels, built loop
    seeds = ",".join(str(s) for s in range(runs))
    profiler = cProfile.Profile()
    with _quiet():
        t0 = time.perf_counter()
        code = profiler.runcall(main, ["sweep", path, "--grid", f"simulation.seed={seeds}", "--jobs", "1", "--json"])
        wall = time.perf_counter() - t0
    print(f"profile of `coopctrl sweep {name} --grid simulation.seed=0,...,{runs - 1} --jobs 1` in process (exit {code}, "
          f"{wall:.2f} s under the profiler, {wall / runs * 1e3:.1f} ms a run); top {top} by cumulative time:")
    pstats.Stats(profiler, stream=sys.stdout).sort_stats("cumulative").print_stats(top)
    print(f"top {top} by own time:")
    pstats.Stats(profiler, stream=sys.stdout).sort_stats("tottime").print_stats(top)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed rounds per scene after a warm-up (default 5)")
    parser.add_argument("--sweep-runs", type=int, default=200, help="runs of the sweep per scene (default 200; 0: none)")
    parser.add_argument("--jobs", type=int, default=2, help="worker processes of the sweep (default 2)")
    parser.add_argument("--quick", action="store_true", help="1 round per scene and a sweep of 4 runs (a smoke run)")
    parser.add_argument("--scenes", default="", help="comma-separated scene names (default: every shipped scene)")
    parser.add_argument("--profile", metavar="SCENE", help="only profile one in-process `coopctrl run SCENE -q` (cProfile, "
                        "top 25 cumulative) and exit")
    parser.add_argument("--profile-sweep", metavar="SCENE", help="only profile an in-process sweep of 40 runs of SCENE "
                        "with --jobs 1 (a worker's per-run cost; cProfile, top 25 cumulative) and exit")
    args = parser.parse_args(argv)
    if args.repeats < 1 or args.sweep_runs < 0 or args.jobs < 1:
        parser.error("--repeats and --jobs must be >= 1, --sweep-runs >= 0")
    if args.quick:
        args.repeats, args.sweep_runs = 1, min(args.sweep_runs, 4)
    scenes = [s for s in args.scenes.split(",") if s] or SCENES
    unknown = [s for s in scenes + [p for p in (args.profile, args.profile_sweep) if p] if s not in SCENES]
    if unknown:
        parser.error(f"unknown scene(s) {', '.join(unknown)}: expected names of scenarios/*.toml ({', '.join(SCENES)})")
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"machine: {platform.machine()}, {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.2f}; "
          f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}")
    if args.profile:
        profile_cli(args.profile)
        return 0
    if args.profile_sweep:
        profile_sweep(args.profile_sweep)
        return 0
    clock = KernelClock()
    if not clock.installed:
        print("note: no kernel clock (coopctrl.loop.run._core.Tick is gone): the ticks column is loop.run")
    results = []
    for name in scenes:
        r = measure_scene(name, args.repeats, args.sweep_runs, args.jobs, clock)
        print_scene(r, clock.installed, args.jobs)
        sys.stdout.flush()
        results.append(r)
    print_overview(results)
    print(f"\nload average at the end {os.getloadavg()[0]:.2f}; runs on a shared machine agree only to about 1.5x "
          "(docs/performance.md): compare the ratios")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
