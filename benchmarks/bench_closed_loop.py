"""Closed-loop real-time factor per shipped scene: the compiled tick beside the reference path.

Run: python benchmarks/bench_closed_loop.py [--repeats N] [--quick] [--scenes a,b] [--charts]

For every shipped scene, the loop the user runs (``closed_loop(scenario).run(x0, duration)``: its
full duration at its own control rate; the spatial carry at 1 kHz, RK4, one substep) is timed
``repeats`` times after a warm-up run, once with the compiled tick (``load_distribution.solver =
"compiled"``, the default) and once with the reference path (the same kernel, stopping at each QP for proxsuite); the
medians are printed side by side with their ratio. Post-processing (``simulate()``'s squeeze) is
not included. ``--charts`` adds, for every spatial scene, the tick in the book's world angles with the book's
forms (``scene.rotations = "book"``: the book's springs and Euler path, the default before charts) and in
rotation charts (the default: geodesic springs, the path on the rotation), alternated (issue 20: a scene in
charts runs at the tick of the book's angles): ``loop.run`` per tick, and the ticks only (the run's
``wall_time_s``, without the set-up and without turning the record back into the book's world coordinates).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import coopctrl
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

REPO = Path(__file__).resolve().parent.parent
SCENES = sorted(p.stem for p in (REPO / "scenarios").glob("*.toml"))


def _time_loop(name: str, solver: str, repeats: int, sets: dict | None = None) -> tuple[float, float, int, str, float]:
    """``(median wall [s], duration [s], ticks, status, median wall of the ticks only [s])`` of the scene's run
    with ``solver`` (and the overrides ``sets``); the ticks only: the run's own ``wall_time_s``, from its first
    tick to its last."""
    scenario = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml",
                                      {"load_distribution.solver": solver, **(sets or {})})
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    duration = scenario.simulation.duration
    rec = loop.run(x0, duration)  # warm-up: numba cache, proxsuite set-up
    walls, tick_walls = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        rec = loop.run(x0, duration)
        walls.append(time.perf_counter() - t0)
        tick_walls.append(rec["wall_time_s"])
    ticks = len(rec["t"])
    simulated = max(ticks - 1, 1) * scenario.simulation.control_period
    return statistics.median(walls), simulated, ticks, rec["status"], statistics.median(tick_walls)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per scene and path after a warm-up (default 3)")
    parser.add_argument("--quick", action="store_true", help="1 timed run per scene and path (a smoke run)")
    parser.add_argument("--scenes", default="", help="comma-separated scene names (default: every shipped scene)")
    parser.add_argument("--charts", action="store_true",
                        help="also time each spatial scene in the book's angles with the book's forms and in "
                             "rotation charts (the default), alternately, and print their ticks side by side")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats = 1
    scenes = [s for s in args.scenes.split(",") if s] or SCENES
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"{'scene':28s} {'status':8s} {'ticks':>6s} | {'compiled RT':>11s} {'us/tick':>8s} | "
          f"{'reference RT':>12s} {'us/tick':>8s} | {'ratio':>6s}")
    for name in scenes:
        wc, sim, ticks, status, _ = _time_loop(name, "compiled", args.repeats)
        wr, _, _, _, _ = _time_loop(name, "proxsuite", args.repeats)
        print(f"{name:28s} {status:8s} {ticks:6d} | {sim / wc:10.1f}x {wc / ticks * 1e6:8.1f} | "
              f"{sim / wr:11.1f}x {wr / ticks * 1e6:8.1f} | {wr / wc:5.1f}x", flush=True)
    print("target: spatial_two_puma_carry (1 kHz, RK4, one substep) >= 50x real time (<= 20 us/tick) and >= 10x the "
          "reference path (issue 10)")
    if args.charts:
        _charts_table(scenes, args.repeats)
    return 0


def _charts_table(scenes: list[str], repeats: int) -> None:
    """The tick of each spatial scene in the book's angles with the book's forms and in rotation charts (the loop
    in a re-centred world chart with geodesic springs, docs/model.md s.2): medians of ``repeats`` runs each, the
    two alternated ``repeats`` times so that a change of the machine's load hits both."""
    print(f"\n{'scene':28s} | {'book us/tick':>12s} | {'charts us/tick':>14s} | {'charts/book':>11s} | "
          f"{'ticks only: book':>16s} {'charts':>7s} {'ratio':>6s}")
    for name in scenes:
        scenario = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml")
        if scenario.space != "spatial":
            continue
        book, charts, book_ticks, charts_ticks = [], [], [], []
        try:
            for _ in range(repeats):
                wb, _, ticks, _, tb = _time_loop(name, "compiled", 1, {"scene.rotations": '"book"'})
                wc, _, _, _, tc = _time_loop(name, "compiled", 1, {"scene.rotations": '"charts"'})
                book_ticks.append(tb / ticks)
                charts_ticks.append(tc / ticks)
                book.append(wb / ticks)
                charts.append(wc / ticks)
        except (ValueError, TypeError) as err:  # a path that only charts can run (through pitch 90 deg)
            print(f"{name:28s} | {'-':>12s} | {'-':>14s} | not in the book's angles: {str(err).splitlines()[0][:50]}")
            continue
        b, c = statistics.median(book), statistics.median(charts)
        bt, ct = statistics.median(book_ticks), statistics.median(charts_ticks)
        print(f"{name:28s} | {b * 1e6:12.2f} | {c * 1e6:14.2f} | {c / b:10.3f}x | {bt * 1e6:16.2f} {ct * 1e6:7.2f} "
              f"{ct / bt:5.3f}x", flush=True)


if __name__ == "__main__":
    raise SystemExit(main())
