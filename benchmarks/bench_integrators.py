"""Closed-loop real-time factor of each integrator on spatial_two_puma_carry, side by side.

Run from the repository root::

    python benchmarks/bench_integrators.py [--repeats 3] [--quick]

Two sets of runs of the whole closed loop (plant, QP, leader, followers at 1 kHz):

1. every integrator at the scene's default step (h = T = 1 ms, one substep);
2. every integrator at its largest stable step of the form T / n (the smallest n in
   1, 2, 4, 8 whose run of the whole scene, 2.5 s, ends "ok"; the controller stays at 1 kHz,
   so h cannot exceed T).

The runs are interleaved (round-robin over the integrators, ``--repeats`` rounds after one
warm-up run each) and the medians are reported with their ratios to RK4, measured in the same
process (docs/performance.md: two runs agree only to ~1.5x, so compare ratios). Also shown: the
cost of one integration step of the plant alone (no controller; the loaded initial state and
zero torque, median of individually timed calls), the predicted stability limit
``predicted_max_step(omega_max)`` at the loaded state, and the object's tracking error, so
that speed is never read without accuracy.
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

REPO = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(REPO))

import coopctrl  # noqa: E402
from coopctrl.integrators import INTEGRATORS as REGISTRY, get_integrator  # noqa: E402
from coopctrl.simulator import closed_loop, simulate  # noqa: E402

from bench_plant import median_us  # noqa: E402

SCENE = REPO / "scenarios" / "spatial_two_puma_carry.toml"
INTEGRATORS = tuple(REGISTRY)  # every built-in scheme
SUBSTEPS = (1, 2, 4, 8)


def load(integrator: str, substeps: int, duration: float):
    return coopctrl.load_scenario(SCENE, {"simulation.integrator": integrator, "simulation.substeps": str(substeps),
                                          "simulation.duration": str(duration)})


def run_set(configs, repeats: int):
    """Round-robin timed runs; per config: (median RT factor, median us/tick, summary of the first run)."""
    scenarios = [load(name, n, duration) for name, n, duration in configs]
    for s in scenarios:  # warm-up: numba cache, proxsuite set-up
        simulate(load(s.simulation.integrator, s.simulation.substeps, 0.02))
    rt = [[] for _ in configs]
    tick = [[] for _ in configs]
    first = [None] * len(configs)
    for _ in range(repeats):
        for k, s in enumerate(scenarios):
            r = simulate(s)
            summary = r.summary()
            if first[k] is None:
                first[k] = summary
            rt[k].append(summary["realtime_factor"] or float("nan"))
            tick[k].append(r.wall_time_s / max(1, len(r.t)) * 1e6)
    return [(statistics.median(rt[k]), statistics.median(tick[k]), first[k]) for k in range(len(configs))]


def plant_step_us(calls: int):
    """Median time [us] of one ``integrator.step`` on the carry's plant alone, per integrator."""
    s = coopctrl.load_scenario(SCENE)
    plant, x0 = s.plant(), np.ascontiguousarray(s.initial_state())
    tau = np.zeros(plant.input_size)
    h = s.simulation.step
    out = {}
    for name in INTEGRATORS:
        scheme = get_integrator(name)
        for _ in range(50):
            scheme.step(plant.rhs, 0.0, x0, tau, h)
        out[name] = median_us(lambda: scheme.step(plant.rhs, 0.0, x0, tau, h), calls)
    return out


def print_table(title, configs, rows, step_us, limits, T):
    print(f"\n{title}")
    ref = next(k for k, c in enumerate(configs) if c[0] == "rk4")
    rt_ref, tick_ref = rows[ref][0], rows[ref][1]
    print(f"{'integrator':17s} {'step':>8s} {'status':>15s} {'RT factor':>10s} {'vs rk4':>7s} {'us/tick':>8s} "
          f"{'vs rk4':>7s} {'plant step':>11s} {'vs rk4':>7s} {'pred. limit':>11s} {'pos err max':>12s}")
    for (name, n, _), (rt, tick, s) in zip(configs, rows):
        status = s["status"] if s["status"] == "ok" else f"{s['status']}@{s['simulated_time_s']:.2f}s"
        limit = limits[name]
        limit_text = "none" if limit == 0 else ("inf" if math.isinf(limit) else f"{limit * 1e3:.2f} ms")
        err = s["object_position_error_max_m"]
        print(f"{name:17s} {T / n * 1e3:6.3f}ms {status:>15s} {rt:9.2f}x {rt / rt_ref:6.2f}x {tick:8.1f} "
              f"{tick / tick_ref:6.2f}x {step_us[name]:8.2f} us {step_us[name] / step_us['rk4']:6.2f}x "
              f"{limit_text:>11s} {err * 1e3 if err is not None else float('nan'):9.4f} mm")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="timed runs per configuration (default 3)")
    parser.add_argument("--quick", action="store_true", help="1 repeat, 0.5 s of simulated time in the timed runs, fewer plant calls")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats
    duration = 0.5 if args.quick else coopctrl.load_scenario(SCENE).simulation.duration
    calls = 2000 if args.quick else 20000
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"machine: {platform.machine()} python {platform.python_version()} numpy {np.__version__}, "
          f"{os.cpu_count()} cpus (load average {os.getloadavg()[0]:.1f}); scene spatial_two_puma_carry, {duration} s simulated, medians of {repeats} run(s)")
    t0 = time.perf_counter()
    scenario = coopctrl.load_scenario(SCENE)
    T = scenario.simulation.control_period
    loop = closed_loop(scenario)
    omega = loop.omega_max(scenario.initial_state())
    limits = {name: get_integrator(name).predicted_max_step(omega) for name in INTEGRATORS}
    step_us = plant_step_us(calls)

    default = [(name, 1, duration) for name in INTEGRATORS]
    rows_default = run_set(default, repeats)
    # the largest stable step T / n: the smallest n whose (untimed) run of the whole scene ends ok
    full = scenario.simulation.duration
    stable = []
    for name in INTEGRATORS:
        for n in SUBSTEPS:
            if simulate(load(name, n, full)).status == "ok":
                stable.append((name, n, duration))
                break
        else:
            stable.append((name, SUBSTEPS[-1], duration))
    rows_stable = run_set(stable, repeats)
    print(f"omega_max at the loaded state: {omega:.1f} rad/s; control period T = {T * 1e3:g} ms; "
          f"set-up and runs took {time.perf_counter() - t0:.1f} s")
    print_table("1. at the default step (h = T)", default, rows_default, step_us, limits, T)
    print_table("2. at the largest stable step T / n, n in 1, 2, 4, 8 (the smallest n that runs ok)", stable,
                rows_stable, step_us, limits, T)
    print("\nRT factor: simulated time / closed-loop wall time (higher is faster); us/tick: wall time per "
          "control period (QP, controllers and the plant's substeps); plant step: one integration step of "
          "the plant alone from the loaded state (the implicit schemes keep their Newton matrix between calls); pred. limit: the integrator's predicted stable step at omega_max "
          "(none = unstable for an undamped mode at any step; the springs' damping is what lets Euler run).")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
