"""Closed-loop real-time factor (plant + QP + leader + followers) per scene, with the QP's share.

Run: python benchmarks/bench_closed_loop.py [--repeats N] [--quick]

Each scene runs its full duration at its own control rate (1 kHz, RK4, one substep for the
spatial carry) ``repeats`` times after a warm-up run; the medians are reported side by side.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import coopctrl
from coopctrl.simulator import simulate

REPO = Path(__file__).resolve().parent.parent
SCENES = ["spatial_two_puma_carry", "spatial_three_arm_carry", "contact_points_only", "planar_two_arm_lift"]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per scene after a warm-up (default 3)")
    parser.add_argument("--quick", action="store_true", help="1 timed run per scene (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats = 1
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    rows = []
    for name in SCENES:
        scenario = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml")
        simulate(scenario)  # warm-up: numba cache, proxsuite set-up
        rt, share, wall, per_tick = [], [], [], []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            r = simulate(scenario)
            elapsed = time.perf_counter() - t0
            s = r.summary()
            rt.append(s["realtime_factor"])
            share.append(s["qp_time_share"])
            wall.append(elapsed)
            per_tick.append(r.wall_time_s / max(1, len(r.t)) * 1e6)
        rows.append((name, scenario.simulation.integrator, scenario.simulation.control_period,
                     statistics.median(rt), statistics.median(share), statistics.median(per_tick),
                     statistics.median(wall)))
    base = rows[0][3]
    print(f"{'scene':26s} {'integ.':6s} {'T [ms]':>6s} {'RT factor':>10s} {'vs carry':>9s} {'QP share':>9s} "
          f"{'us/tick':>8s} {'simulate() [s]':>15s}")
    for name, integ, T, rt, share, tick, wall in rows:
        print(f"{name:26s} {integ:6s} {T * 1e3:6.2f} {rt:9.2f}x {rt / base:8.2f}x {share * 100:8.1f}% {tick:8.1f} {wall:15.3f}")
    print("target: >= 20x real time for spatial_two_puma_carry at 1 kHz with RK4 (PERFORMANCE.md: MuJoCo's "
          "plant alone, RK4 at 1 ms, runs 23x real time on this machine class)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
