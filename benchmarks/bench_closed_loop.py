"""Closed-loop real-time factor per shipped scene: the compiled tick beside the reference path.

Run: python benchmarks/bench_closed_loop.py [--repeats N] [--quick] [--scenes a,b] [--charts] [--mujoco]
         [--against CHECKOUT]

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

``--mujoco`` adds, for every scene MuJoCo runs (``coopctrl.mujoco``, ``pip install 'coopctrl[mujoco]'``), MuJoCo's
plant alone with its RK4 integrator at the scene's plant step and zero torques (``mj_step`` of the model
``export-mjcf`` writes), beside the real-time factor ``coopctrl run`` prints (simulated time over the run's own
``wall_time_s``: its ticks) and that of the whole ``loop.run`` (the per-run set-up included), and the ratio of the
printed one to MuJoCo's (issue 42: at least 2x).

``--against CHECKOUT`` times the same scenes' compiled tick with another checkout's interpreter
(``CHECKOUT/.venv/bin/python``, e.g. a worktree of an earlier commit) and this one's, alternated round by round in
fresh processes, and prints the medians of the ticks (``wall_time_s`` per tick) and their ratio: a change's tick
against the tick it replaced, on the same machine at the same time.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
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
    parser.add_argument("--mujoco", action="store_true", help="also MuJoCo's plant alone with RK4 (see above)")
    parser.add_argument("--against", default="", metavar="CHECKOUT",
                        help="time the compiled tick against this other checkout's, alternated (see above)")
    parser.add_argument("--child", default="", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats = 1
    if args.child:  # one timing in a fresh process, for --against: JSON on stdout
        wall, simulated, ticks, status, tick_wall = _time_loop(args.child, "compiled", 1)
        print(json.dumps({"tick_s": tick_wall / ticks, "status": status}))
        return 0
    scenes = [s for s in args.scenes.split(",") if s] or SCENES
    if args.against:
        return _against(scenes, Path(args.against), max(args.repeats, 1))
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
    if args.mujoco:
        _mujoco_table(scenes, args.repeats)
    if args.charts:
        _charts_table(scenes, args.repeats)
    return 0


def _against(scenes: list[str], checkout: Path, repeats: int) -> int:
    """The compiled tick of each scene with this checkout's interpreter and with ``checkout``'s, one fresh process
    each per round, alternated ``repeats`` rounds: medians of the ticks [us] and their ratio (this / that)."""
    other = checkout / ".venv" / "bin" / "python"
    if not other.exists():
        print(f"--against {checkout}: no interpreter at {other}", file=sys.stderr)
        return 2
    script = str(Path(__file__).resolve())
    print(f"the compiled tick: this checkout ({REPO}) against {checkout}, {repeats} alternated rounds, fresh processes")
    print(f"{'scene':28s} | {'this us/tick':>12s} | {'that us/tick':>12s} | {'this/that':>9s}")
    for name in scenes:
        mine, theirs = [], []
        for _ in range(repeats):
            for python, out, cwd in ((sys.executable, mine, REPO), (str(other), theirs, checkout)):
                done = subprocess.run([python, script, "--child", name], cwd=cwd, capture_output=True, text=True)
                if done.returncode != 0:
                    print(f"{name}: {python} failed: {done.stderr.strip().splitlines()[-1:]}", file=sys.stderr)
                    return 1
                out.append(json.loads(done.stdout.strip().splitlines()[-1])["tick_s"])
        a, b = statistics.median(mine), statistics.median(theirs)
        print(f"{name:28s} | {a * 1e6:12.2f} | {b * 1e6:12.2f} | {a / b:8.3f}x", flush=True)
    print("target (issue 42): the compiled core's tick no slower than the numba tick it replaced (this/that <= 1)")
    return 0


def _mujoco_table(scenes: list[str], repeats: int) -> None:
    """MuJoCo's plant alone with RK4 at each scene's plant step, zero torques, against the compiled loop's
    real-time factor (medians of ``repeats``)."""
    try:
        import mujoco

        from coopctrl.mujoco.closed_loop import check_scene
        from coopctrl.mujoco.plant import MujocoPlant
    except ImportError:
        print("\n--mujoco: MuJoCo is not installed (pip install 'coopctrl[mujoco]')")
        return
    print(f"\n{'scene':28s} | {'run RT':>8s} | {'loop.run RT':>11s} | {'MuJoCo RK4 plant RT':>19s} | "
          f"{'run / MuJoCo':>12s}")
    for name in scenes:
        scenario = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml")
        try:
            check_scene(scenario)
        except Exception as err:  # a scene MuJoCo's plant does not model
            print(f"{name:28s} | not on MuJoCo: {str(err).splitlines()[0][:60]}")
            continue
        wc, sim, _, _, w_ticks = _time_loop(name, "compiled", repeats)
        mp = MujocoPlant(scenario)
        mp.model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        h = scenario.simulation.control_period / scenario.simulation.substeps
        mp.model.opt.timestep = h
        steps = int(round(sim / h))
        walls = []
        for _ in range(max(repeats, 1)):
            mujoco.mj_resetData(mp.model, mp.data)
            t0 = time.perf_counter()
            mujoco.mj_step(mp.model, mp.data, nstep=steps)
            walls.append(time.perf_counter() - t0)
        wm = statistics.median(walls)
        print(f"{name:28s} | {sim / w_ticks:7.1f}x | {sim / wc:10.1f}x | {sim / wm:18.1f}x | {wm / w_ticks:11.2f}x",
              flush=True)
    print("target (issue 42): the real-time factor coopctrl run prints >= 2x MuJoCo's plant alone with RK4")


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
