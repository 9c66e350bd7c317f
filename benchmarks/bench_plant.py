"""Benchmark: one evaluation of the cooperative plant's right-hand side.

Run from the repository root::

    python benchmarks/bench_plant.py [--calls 20000] [--quick]

For each scene (built with ``tests/_scenes.py``) it prints the median time of one warm
``plant.rhs(t, x, tau)`` call (the Python wrapper with its status check) and of the raw numba
``plant.kernel`` call ``fn(x, tau, *args)``, over ``--calls`` individually timed calls, side by
side in one run, with ratios to the first scene (PERFORMANCE.md: runs agree only to ~1.5x, so
compare ratios measured in one run). MuJoCo's per-step figures from /work/shared/PERFORMANCE.md
are printed for scale: an RK4 step costs four right-hand-side evaluations, an explicit Euler
step one.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "tests"))

from _scenes import scene  # noqa: E402

#: MuJoCo 4.0, two 6-DOF arms holding a welded object, plant only, 1 ms step (PERFORMANCE.md).
MUJOCO_US_PER_STEP = {"Euler": 21.0, "implicitfast": 18.0, "RK4": 44.0}

SCENES = [
    ("2 x Puma 560 + object (spatial, mobile)", dict(space="spatial", m=2, arms="full")),
    ("2 x planar 3R + object (planar)", dict(space="planar", m=2, arms="full")),
    ("2 contact points + object (spatial)", dict(space="spatial", m=2, arms="contact")),
    ("3 x Puma 560 + object (spatial, m = 3)", dict(space="spatial", m=3, arms="full")),
]


def median_us(fn, calls):
    times = np.empty(calls)
    clock = time.perf_counter
    for i in range(calls):
        t0 = clock()
        fn()
        times[i] = clock() - t0
    return float(np.median(times)) * 1e6


def timer_overhead_us(calls):
    return median_us(lambda: None, calls)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=20000, help="timed calls per scene (default 20000)")
    ap.add_argument("--quick", action="store_true", help="2000 timed calls per scene (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.calls = min(args.calls, 2000)
    print(f"command: {' '.join(['python', *sys.argv])}")
    print(f"machine: {platform.machine()} {platform.processor() or ''} python {platform.python_version()} "
          f"numpy {np.__version__}, {os.cpu_count()} cpus")
    t0 = time.perf_counter()
    rows = []
    rng = np.random.default_rng(0)
    for label, kw in SCENES:
        plant, x0 = scene(**kw)
        x = x0.copy()
        nq = plant.input_size
        x[:nq] += rng.normal(0.0, 0.02, nq)
        x[plant.nz:] = rng.normal(0.0, 0.1, plant.nz)
        x = np.ascontiguousarray(x)
        tau = rng.normal(0.0, 1.0, nq)
        fn, extra = plant.kernel
        # warm: compile (or load from the numba cache) before timing
        plant.rhs(0.0, x, tau)
        fn(x, tau, *extra)
        for _ in range(200):
            plant.rhs(0.0, x, tau)
            fn(x, tau, *extra)
        rhs_us = median_us(lambda: plant.rhs(0.0, x, tau), args.calls)
        raw_us = median_us(lambda: fn(x, tau, *extra), args.calls)
        rows.append((label, plant.state_size, rhs_us, raw_us))
    overhead = timer_overhead_us(args.calls)
    print(f"set-up and warm-up (scenes, IK, numba cache): {time.perf_counter() - t0:.1f} s; "
          f"timer overhead {overhead:.2f} us per call (included below)\n")
    base_rhs, base_raw = rows[0][2], rows[0][3]
    print(f"{'scene':44s} {'states':>6s} {'rhs [us]':>9s} {'kernel [us]':>11s} {'rhs/ref':>8s} {'kern/ref':>8s} "
          f"{'wrapper':>8s}")
    for label, n, r, k in rows:
        print(f"{label:44s} {n:6d} {r:9.2f} {k:11.2f} {r / base_rhs:8.2f} {k / base_raw:8.2f} {r - k:7.2f}us")
    print("\nMuJoCo 4.0 for scale (two 6-DOF arms + welded object, plant only, per 1 ms step):")
    puma_raw = rows[0][3]
    for name, us in MUJOCO_US_PER_STEP.items():
        evals = 4 if name == "RK4" else 1
        print(f"  {name:13s} {us:5.1f} us/step | our 2-Puma plant, rhs evaluations of one such step "
              f"({evals}): {evals * puma_raw:6.2f} us | MuJoCo/ours {us / (evals * puma_raw):4.1f}x")
    print("(MuJoCo figures are from /work/shared/PERFORMANCE.md, measured on a machine of the same class,"
          " not in this run: compare orders of magnitude only.)")


if __name__ == "__main__":
    main()
