"""Run the benchmarks the documentation quotes and write their table: docs/data/benchmarks.md.

Run: python benchmarks/run_all.py [--quick] [--repeats N] [--out FILE] [--no-readme]

Three measurements, each timed side by side in this one run (medians of ``repeats`` runs after a warm-up
run that loads the compiled kernels, or compiles them on an empty cache):

1. the closed loop per scene: the loop the user runs (``closed_loop(scenario).run(x0, duration)``, the
   scene's whole duration) with the compiled QP in the compiled tick, beside the reference path (the same
   tick, the QP solved by proxsuite in Python): microseconds per tick, real-time factor and their ratio, and
   the compiled tick's CPU time (which a busy machine's waiting for a core does not inflate);
2. the integrators on the two-Puma carry: microseconds per tick for each scheme, and the ratio to RK4;
3. the load-distribution QP per solve: the compiled Goldfarb-Idnani solver called from a compiled loop
   (warm started), beside proxsuite from Python, on seeded sequences of the loop's problems.

The table (machine, date, versions, medians, ratios) goes to ``--out`` (default docs/data/benchmarks.md,
which docs/benchmarks.md includes); the headline (the carry's real-time factor and tick) is also written
into README.md between its ``benchmark-headline`` markers, unless ``--no-readme``. Nothing is typed by
hand: rerun this command to refresh both. Times depend on the machine and its load; ratios measured side by
side in one run move less.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

QUICK_SCENES = ("planar_two_arm_lift", "spatial_two_puma_carry", "two_panda_carry")
QUICK_INTEGRATORS = ("rk4", "euler", "symplectic_euler")
ALL_INTEGRATORS = ("rk4", "euler", "symplectic_euler", "implicit_midpoint", "implicit_euler", "rk23", "rk45", "trbdf2")
CARRY = "spatial_two_puma_carry"
HEADLINE = re.compile(r"(<!-- benchmark-headline -->\n)(.*?)(\n<!-- /benchmark-headline -->)", re.S)


def _cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _commit() -> str:
    try:
        out = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True, text=True,
                             timeout=10)
        return out.stdout.strip() or "unknown"
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def machine() -> dict[str, str]:
    """What the figures were measured on."""
    import numpy
    import scipy

    from importlib.metadata import version

    return {
        "date": datetime.datetime.now(datetime.timezone.utc).date().isoformat(),
        "machine": f"{_cpu_model()}, {os.cpu_count()} logical CPUs, {platform.system()} {platform.machine()}",
        "versions": (f"coopctrl {version('coopctrl')} ({_commit()}), Python {platform.python_version()}, "
                     f"numpy {numpy.__version__}, scipy {scipy.__version__}, "
                     f"proxsuite {version('proxsuite')}"),
    }


def time_loop(name: str, repeats: int, sets: dict) -> tuple[float, float, int, str, float]:
    """``(median wall [s], simulated time [s], ticks, status, median CPU time of this process [s])`` of
    ``closed_loop(scenario).run`` over the scene's duration, after one warm-up run. The CPU time leaves out
    the time the process waited for a core, which the wall time counts on a busy machine."""
    import coopctrl
    from coopctrl.scenario import build
    from coopctrl.simulator import closed_loop

    scenario = coopctrl.load_scenario(name, sets)
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    duration = scenario.simulation.duration
    record = loop.run(x0, duration)  # warm-up: the kernels loaded (or compiled), the solver set up
    walls, cpus = [], []
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        record = loop.run(x0, duration)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    ticks = len(record["t"])
    return (statistics.median(walls), max(ticks - 1, 1) * scenario.simulation.control_period, ticks, record["status"],
            statistics.median(cpus))


def closed_loop_rows(scenes, repeats: int) -> list[dict]:
    rows = []
    for name in scenes:
        compiled = time_loop(name, repeats, {"load_distribution.solver": "compiled"})
        reference = time_loop(name, repeats, {"load_distribution.solver": "proxsuite"})
        rows.append({"scene": name, "status": compiled[3], "ticks": compiled[2],
                     "compiled_us": compiled[0] / compiled[2] * 1e6, "compiled_rt": compiled[1] / compiled[0],
                     "reference_us": reference[0] / reference[2] * 1e6, "reference_rt": reference[1] / reference[0],
                     "compiled_cpu_us": compiled[4] / compiled[2] * 1e6})
        print(f"closed loop  {name:<28} {rows[-1]['compiled_us']:8.1f} us/tick compiled, "
              f"{rows[-1]['reference_us']:8.1f} us/tick reference", file=sys.stderr)
    return rows


def integrator_rows(integrators, repeats: int) -> list[dict]:
    rows = []
    for integrator in integrators:
        wall, simulated, ticks, status, _ = time_loop(CARRY, repeats, {"simulation.integrator": integrator})
        rows.append({"integrator": integrator, "status": status, "us": wall / ticks * 1e6, "rt": simulated / wall})
        print(f"integrator   {integrator:<28} {rows[-1]['us']:8.1f} us/tick", file=sys.stderr)
    return rows


def qp_rows(arm_counts, steps: int, repeats: int) -> list[dict]:
    from bench_compiled_qp import Sequence, bench_compiled_loop, bench_proxsuite, trajectory_problems

    seqs = [trajectory_problems(m, steps) for m in arm_counts]
    warm = seqs[0]
    bench_compiled_loop(Sequence("warm-up", warm.P, warm.g[:2], warm.M[:2], warm.lo[:2], warm.hi[:2], warm.n_eq), 1)
    rows = []
    for m, seq in zip(arm_counts, seqs):
        loop_us, _, _ = bench_compiled_loop(seq, repeats)
        prox_us, _ = bench_proxsuite(seq)
        rows.append({"problem": seq.name, "n": seq.P.shape[0], "rows": seq.M.shape[1], "compiled_us": loop_us,
                     "proxsuite_us": prox_us})
        print(f"QP           m = {m}: {loop_us:8.2f} us compiled, {prox_us:8.2f} us proxsuite", file=sys.stderr)
    return rows


def _fmt(value: float) -> str:
    return f"{value:.3g}" if value < 100 else f"{value:.0f}"


def table(info: dict, command: str, repeats: int, loops: list[dict], integrators: list[dict], qps: list[dict]) -> str:
    """The results as Markdown (what docs/benchmarks.md includes)."""
    out = [
        "<!-- written by benchmarks/run_all.py; do not edit by hand: rerun the command below -->",
        "",
        "| | |", "|---|---|",
        f"| command | `{command}` |",
        f"| date (UTC) | {info['date']} |",
        f"| machine | {info['machine']} |",
        f"| versions | {info['versions']} |",
        f"| medians of | {repeats} timed runs after a warm-up, side by side in one run |",
        "",
        "**The closed loop per scene** (the scene's whole duration; the compiled QP in the compiled tick, beside "
        "the reference path with proxsuite):",
        "",
        "| scene | status | ticks | compiled us/tick | compiled x real time | reference us/tick | reference x real time "
        "| ratio | compiled CPU us/tick |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in loops:
        out.append(f"| `{r['scene']}` | {r['status']} | {r['ticks']} | {_fmt(r['compiled_us'])} | {_fmt(r['compiled_rt'])} "
                   f"| {_fmt(r['reference_us'])} | {_fmt(r['reference_rt'])} | {r['reference_us'] / r['compiled_us']:.1f}x "
                   f"| {_fmt(r['compiled_cpu_us'])} |")
    rk4 = next((r["us"] for r in integrators if r["integrator"] == "rk4"), None)
    out += ["", f"**The integrators on `{CARRY}`** (one step per control period):", "",
            "| integrator | status | us/tick | x real time | ratio to rk4 |", "|---|---|---|---|---|"]
    for r in integrators:
        ratio = f"{r['us'] / rk4:.2f}" if rk4 else "-"
        out.append(f"| `{r['integrator']}` | {r['status']} | {_fmt(r['us'])} | {_fmt(r['rt'])} | {ratio} |")
    out += ["", "**The load-distribution QP per solve** (seeded sequences of the loop's problems, grip, friction and "
            "torque rows; the compiled solver warm started inside a compiled loop, proxsuite from Python):", "",
            "| problem | variables | rows | compiled us | proxsuite us | ratio |", "|---|---|---|---|---|---|"]
    for r in qps:
        out.append(f"| {r['problem']} | {r['n']} | {r['rows']} | {r['compiled_us']:.2f} | {r['proxsuite_us']:.1f} "
                   f"| {r['proxsuite_us'] / r['compiled_us']:.1f}x |")
    return "\n".join(out) + "\n"


def headline(loops: list[dict], data_file: str) -> str:
    """The README's one sentence of figures, from this run."""
    carry = next(r for r in loops if r["scene"] == CARRY)
    return (f"The two-Puma carry runs at **{_fmt(carry['compiled_rt'])}x real time** ({_fmt(carry['compiled_us'])} us "
            f"per 1 ms tick), {carry['reference_us'] / carry['compiled_us']:.1f}x faster than the same tick with the "
            f"QP solved in Python (`{data_file}`).")


def write_headline(readme: Path, sentence: str) -> bool:
    text = readme.read_text(encoding="utf-8")
    if not HEADLINE.search(text):
        return False
    readme.write_text(HEADLINE.sub(lambda m: m.group(1) + sentence + m.group(3), text), encoding="utf-8")
    return True


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true",
                        help=f"three scenes ({', '.join(QUICK_SCENES)}), the explicit integrators, two QP sizes, "
                             "3 repeats (a few minutes on a warm cache)")
    parser.add_argument("--repeats", type=int, default=None, help="timed runs per measurement (default 5; 3 with --quick)")
    parser.add_argument("--out", default=str(REPO / "docs" / "data" / "benchmarks.md"), metavar="FILE",
                        help="the Markdown table to write (default docs/data/benchmarks.md)")
    parser.add_argument("--no-readme", action="store_true", help="leave README.md's headline as it is")
    args = parser.parse_args(argv)
    repeats = args.repeats if args.repeats is not None else (3 if args.quick else 5)
    if repeats < 1:
        parser.error(f"--repeats {repeats}: expected an integer >= 1")
    out = Path(args.out)
    if not out.parent.is_dir():
        parser.error(f"--out {args.out!r}: its folder does not exist")
    scenes = QUICK_SCENES if args.quick else tuple(sorted(p.stem for p in (REPO / "scenarios").glob("*.toml")
                                                          if p.stem != "central_spring_buckling"))
    if CARRY not in scenes:
        scenes = (*scenes, CARRY)
    command = "python benchmarks/run_all.py" + (" --quick" if args.quick else "") + (
        f" --repeats {args.repeats}" if args.repeats is not None else "")
    info = machine()
    loops = closed_loop_rows(scenes, repeats)
    integrators = integrator_rows(QUICK_INTEGRATORS if args.quick else ALL_INTEGRATORS, repeats)
    qps = qp_rows((2, 4) if args.quick else (2, 3, 4), 300 if args.quick else 2000, repeats)
    text = table(info, command, repeats, loops, integrators, qps)
    out.write_text(text, encoding="utf-8")
    print(text)
    try:
        shown = out.resolve().relative_to(REPO).as_posix()
    except ValueError:
        shown = out.name
    if not args.no_readme and out.resolve() == (REPO / "docs" / "data" / "benchmarks.md").resolve():
        write_headline(REPO / "README.md", headline(loops, shown))
    return 0


if __name__ == "__main__":
    sys.exit(main())
