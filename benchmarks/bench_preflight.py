"""Pre-flight's cost per shipped scene, beside the scene's ticks.

Run: python benchmarks/bench_preflight.py [--repeats N] [--scenes a,b]

For every shipped scene, ``preflight(scenario)`` as ``coopctrl run`` calls it (the loop built inside,
the compiled kernels already loaded by a warm-up call) and the ticks alone (``closed_loop(scenario).run(x0,
duration)``, its full duration, after a warm-up run) are each timed ``repeats`` times; the medians are
printed with their ratio and the number of instants pre-flight checked. Target (issue 18):
``spatial_two_puma_carry`` pre-flight at most 10 ms, its instants bounded whatever the duration.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import coopctrl
from coopctrl.analysis.preflight import preflight
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

from _scene_options import SCENES, add_scene_options, chosen_scenarios



def _median_s(call, repeats: int) -> float:
    """Median wall time [s] of ``call()`` over ``repeats`` calls after one warm-up call."""
    call()
    walls = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        call()
        walls.append(time.perf_counter() - t0)
    return statistics.median(walls)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_scene_options(parser, 9, "timed calls per scene after a warm-up",
                      "comma-separated scene names (default: every shipped scene)")
    args = parser.parse_args(argv)
    scenarios = chosen_scenarios(parser, args, SCENES)  # every scene checked before any work
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}; "
          f"coopctrl from {Path(coopctrl.__file__).parent}")
    print(f"{'scene':28s} {'instants':>8s} {'pre-flight ms':>13s} {'ticks ms':>9s} {'pre-flight/ticks':>16s}")
    for name, scenario in scenarios.items():
        report = preflight(scenario)
        pre = _median_s(lambda: preflight(scenario), args.repeats)
        loop = closed_loop(scenario)
        x0 = build.initial_state(scenario)
        ticks = _median_s(lambda: loop.run(x0, scenario.simulation.duration), args.repeats)
        print(f"{name:28s} {report.samples:8d} {pre * 1e3:13.2f} {ticks * 1e3:9.2f} {pre / ticks:16.3f}", flush=True)
    print("target: spatial_two_puma_carry pre-flight <= 10 ms (issue 18)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
