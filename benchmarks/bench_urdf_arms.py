"""Per-tick cost of the two-Panda carry (7-joint URDF arms) against the two-Puma carry.

Run from the repository root::

    python benchmarks/bench_urdf_arms.py [--repeats N] [--quick]

Both scenes run their full duration (2.5 s at 1 kHz, RK4, one substep) through the closed loop
as it is (plant kernels compiled, the loop in Python): ``two_panda_carry`` (two Franka Pandas,
URDF, redundancy resolution with a null-space posture task) and ``spatial_two_puma_carry``
(two Puma 560, DH). After one warm-up run each, the runs alternate (Puma, Panda, Puma, ...) so
that machine load affects both alike; the medians of the per-tick wall time
(``wall_time_s / ticks``) and their ratio are printed. Target (issue 13): ratio <= 1.3.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

from coopctrl import load_scenario  # noqa: E402
from coopctrl.simulator import simulate  # noqa: E402

SCENES = ("spatial_two_puma_carry", "two_panda_carry")
TARGET = 1.3


def per_tick_us(scenario) -> float:
    r = simulate(scenario)
    if r.status != "ok":
        raise SystemExit(f"{scenario.name}: run not ok ({r.reason})")
    return r.wall_time_s / max(1, len(r.t)) * 1e6


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per scene (default 5)")
    parser.add_argument("--quick", action="store_true", help="one timed run per scene (a smoke run)")
    args = parser.parse_args(argv)
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, python {platform.python_version()}")
    scenarios = {name: load_scenario(REPO / "scenarios" / f"{name}.toml") for name in SCENES}
    for s in scenarios.values():
        per_tick_us(s)  # warm-up: numba cache, solver set-up
    times = {name: [] for name in SCENES}
    for _ in range(1 if args.quick else args.repeats):
        for name in SCENES:
            times[name].append(per_tick_us(scenarios[name]))
    puma, panda_ = (statistics.median(times[n]) for n in SCENES)
    print(f"{'scene':24s} {'arms':18s} {'us/tick (median)':>17s}")
    print(f"{SCENES[0]:24s} {'2 x Puma 560 (6)':18s} {puma:17.1f}")
    print(f"{SCENES[1]:24s} {'2 x Panda (7)':18s} {panda_:17.1f}")
    ratio = panda_ / puma
    print(f"ratio Panda / Puma per tick: {ratio:.2f}x (target <= {TARGET}x: {'met' if ratio <= TARGET else 'NOT met'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
