"""The controller's step from Python beside the loop's own tick, on the carry.

Run: python benchmarks/bench_controller_step.py [--repeats N] [--quick] [--scenes a,b]

For each scene (default: ``spatial_two_puma_carry``), the loop runs the whole scene once
(``closed_loop(scenario).run``) and its measurements of every tick (state and measured wrenches) are
turned into :class:`coopctrl.Measurement` objects beforehand. Then, ``repeats`` times, alternated:

* **step**: ``controller.step(t, measurement)`` on every tick from a fresh state, each call timed with
  ``perf_counter`` (the median over all the calls of all the repeats);
* **step + measurement**: the same with the :class:`~coopctrl.Measurement` built from the state in the
  timed call (``controller.measurement(x, F)``), as a driver that reads its sensors into one each period;
* **steps, pass**: a whole pass of steps over the scene, its wall time per step (the loop's measure);
* **loop tick, run**: the loop's run, its ticks only (``wall_time_s / ticks``: sensors, guards, QP, controllers,
  record and the plant's RK4 advance; no call from Python per tick).

The first two are medians of single calls (robust to a busy machine); the last two are whole passes (a
busy machine's preemptions fall in them): compare the pass with the run.

Target (issue 43): at most 15 us per step from Python on the carry.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import coopctrl
from coopctrl import wiring
from coopctrl.scenario import build

REPO = Path(__file__).resolve().parent.parent

#: Target of one step from Python on the carry [us] (issue 43).
TARGET_US = 15.0


def _bench(name: str, repeats: int) -> dict:
    scenario = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml")
    loop = wiring.closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    duration = scenario.simulation.duration
    rec = loop.run(x0, duration)  # warm-up, and the measurements
    controller = coopctrl.Controller(scenario)
    T = controller.control_period
    times = [k * T for k in range(len(rec["t"]))]
    meas = [controller.measurement(x, F) for x, F in zip(rec["x"], rec["F_measured"])]
    fresh = controller.state
    perf = time.perf_counter
    step_us, built_us, tick_us, pass_us = [], [], [], []
    for k in range(len(meas)):  # warm-up: every branch the run takes
        controller.step(times[k], meas[k])
    step = controller.step
    for _ in range(repeats):
        controller.state = fresh
        for k in range(len(meas)):
            t0 = perf()
            step(times[k], meas[k])
            step_us.append(perf() - t0)
        controller.state = fresh
        t0 = perf()
        for k in range(len(meas)):
            step(times[k], meas[k])
        pass_us.append((perf() - t0) / len(meas))
        controller.state = fresh
        xs, Fs = rec["x"], rec["F_measured"]
        for k in range(len(meas)):
            t0 = perf()
            controller.step(times[k], controller.measurement(xs[k], Fs[k]))
            built_us.append(perf() - t0)
        run = loop.run(x0, duration)
        tick_us.append(run["wall_time_s"] / len(run["t"]))
    return {"ticks": len(meas), "step": statistics.median(step_us) * 1e6,
            "step_p90": float(np.percentile(step_us, 90)) * 1e6,
            "built": statistics.median(built_us) * 1e6, "tick": statistics.median(tick_us) * 1e6,
            "pass": statistics.median(pass_us) * 1e6}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed passes over the scene (default 5)")
    parser.add_argument("--quick", action="store_true", help="1 timed pass (a smoke run)")
    parser.add_argument("--scenes", default="spatial_two_puma_carry", help="comma-separated scene names")
    args = parser.parse_args(argv)
    if args.quick:
        args.repeats = 1
    scenes = [s for s in args.scenes.split(",") if s]
    for name in scenes:
        if not (REPO / "scenarios" / f"{name}.toml").is_file():
            print(f"error: --scenes: {name!r} is not a shipped scene (scenarios/*.toml)", file=sys.stderr)
            return 2
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"{'scene':26s} {'ticks':>6s} | {'step [us]':>9s} {'p90':>6s} | {'+ measurement':>13s} | "
          f"{'steps, pass':>11s} | {'loop tick, run':>14s}")
    for name in scenes:
        r = _bench(name, args.repeats)
        print(f"{name:26s} {r['ticks']:6d} | {r['step']:9.2f} {r['step_p90']:6.2f} | {r['built']:13.2f} | "
              f"{r['pass']:11.2f} | {r['tick']:14.2f}", flush=True)
    print(f"target: at most {TARGET_US:g} us per step from Python on spatial_two_puma_carry (medians of every call)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
