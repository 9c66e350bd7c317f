"""Benchmark: one evaluation of the cooperative plant's right-hand side, from Python, in the compiled core.

Run from the repository root::

    python benchmarks/bench_plant.py [--calls 20000] [--quick]

For the two-Puma carry and every other shipped scene (``scenarios/*.toml``, built as ``coopctrl run``
builds them, at a perturbed initial state), side by side in one run, it prints the median cost of
one right-hand side [us]:

* ``python``: ``plant.rhs(t, x, tau)`` (the Python wrapper: its size checks, one call of the core, the status check);
* ``core``: the compiled core's right-hand side called directly from Python (``plants._core.spatial_rhs`` or
  ``planar_rhs`` on the plant's arrays, ``plant.plant_args``, into a preallocated ``dx``): what remains of a call
  without the wrapper, the binding's crossing included (the tick calls the same C++ function without it);
* ``RK4``: four ``core`` evaluations (one RK4 step of the plant).

The figures are medians of individually timed calls (docs/performance.md: runs agree only to ~1.5x, so compare
ratios measured in one run). MuJoCo's per-step figures are printed for scale: MuJoCo 4.0, plant only
(two 6-DOF arms holding a welded object, no controller), 1 ms step, medians on a quiet 2-core AMD EPYC
machine of the class this project is developed on, measured on 2026-12-01: RK4 24 us per step (41x real
time), Euler 6.2 us, implicitfast 6.8 us (docs/performance.md). They are not measured by this script.
"""

from __future__ import annotations

import argparse
import glob
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, ROOT)

#: MuJoCo 4.0, two 6-DOF arms holding a welded object, plant only, 1 ms step: medians [us per step] on a
#: quiet 2-core machine of this class, measured on 2026-12-01 (docs/performance.md).
MUJOCO_US_PER_STEP = {"Euler": 6.2, "implicitfast": 6.8, "RK4": 24.0}
#: The scene the target is stated for, listed first.
CARRY = "spatial_two_puma_carry"
#: Scenes of a --quick run (one per kind of plant).
QUICK_SCENES = (CARRY, "planar_two_arm_lift", "contact_points_only", "two_panda_carry")
def median_us(fn, calls):
    times = np.empty(calls)
    clock = time.perf_counter
    for i in range(calls):
        t0 = clock()
        fn()
        times[i] = clock() - t0
    return float(np.median(times)) * 1e6


def scene_names(quick):
    names = sorted(os.path.splitext(os.path.basename(p))[0] for p in glob.glob(os.path.join(ROOT, "scenarios", "*.toml")))
    if quick:
        names = [n for n in QUICK_SCENES if n in names]
    return [CARRY] + [n for n in names if n != CARRY]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=20000, help="individually timed calls per figure (default 20000)")
    ap.add_argument("--quick", action="store_true", help="2000 calls, four scenes (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.calls = min(args.calls, 2000)
    print(f"command: {' '.join(['python', *sys.argv])}")
    print(f"machine: {platform.machine()} {platform.processor() or ''} python {platform.python_version()} "
          f"numpy {np.__version__}, {os.cpu_count()} cpus, load average {os.getloadavg()[0]:.2f}")
    t0 = time.perf_counter()
    from coopctrl import load_scenario
    from plants import _core

    rng = np.random.default_rng(0)
    rows = []
    for name in scene_names(args.quick):
        s = load_scenario(os.path.join(ROOT, "scenarios", f"{name}.toml"))
        plant = s.plant()
        x = np.array(s.initial_state(), dtype=float)
        nq = plant.input_size
        x[:nq] += rng.normal(0.0, 0.02, nq)
        x[plant.nz:] = rng.normal(0.0, 0.1, plant.nz)
        x = np.ascontiguousarray(x)
        tau = rng.normal(0.0, 1.0, nq)
        core_rhs = _core.spatial_rhs if plant.space == "spatial" else _core.planar_rhs
        P, dx = plant.plant_args, np.empty_like(x)
        status = core_rhs(x, tau, P, dx)
        assert status[0] == 0, (name, status)
        np.testing.assert_array_equal(dx, plant.rhs(0.0, x, tau))  # the wrapper calls the same function
        for _ in range(200):
            plant.rhs(0.0, x, tau)
            core_rhs(x, tau, P, dx)
        rhs_us = median_us(lambda: plant.rhs(0.0, x, tau), args.calls)
        core_us = median_us(lambda: core_rhs(x, tau, P, dx), args.calls)
        rows.append((name, plant.state_size, rhs_us, core_us))
    print(f"set-up (scenes): {time.perf_counter() - t0:.1f} s; {args.calls} calls per figure\n")
    print(f"{'scene':32s} {'states':>6s} {'python':>8s} {'core':>8s} {'RK4':>8s}   [us per right-hand side]")
    for name, n, r, c in rows:
        print(f"{name:32s} {n:6d} {r:8.2f} {c:8.2f} {4 * c:8.2f}")
    carry = rows[0]
    print(f"\n{CARRY}: {carry[3]:.2f} us per right-hand side in the core (called from Python); "
          f"{carry[2]:.2f} us through plant.rhs")
    print("\nMuJoCo 4.0 for scale (two 6-DOF arms + welded object, plant only, per 1 ms step):")
    for mname, us in MUJOCO_US_PER_STEP.items():
        evals = 4 if mname == "RK4" else 1
        print(f"  {mname:13s} {us:5.1f} us/step | the carry's core rhs evaluations of one such step "
              f"({evals}): {evals * carry[3]:6.2f} us | MuJoCo/ours {us / (evals * carry[3]):4.1f}x")
    print("(MuJoCo figures: docs/performance.md, medians measured on 2026-12-01 on a 2-core machine of the same class,"
          " not in this run: compare orders of magnitude only.)")


if __name__ == "__main__":
    main()
