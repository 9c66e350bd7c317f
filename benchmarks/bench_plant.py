"""Benchmark: one evaluation of the cooperative plant's right-hand side, from Python and inside a compiled loop.

Run from the repository root::

    python benchmarks/bench_plant.py [--calls 20000] [--repeats 9] [--quick]

For the two-Puma carry and every other shipped scene (``scenarios/*.toml``, built as ``coopctrl run``
builds them, at a perturbed initial state), side by side in one run, it prints the median cost of
one right-hand side [us]:

* ``python``: ``plant.rhs(t, x, tau)`` (the Python wrapper with its status check);
* ``kernel``: the raw numba ``plant.kernel`` called from Python (``fn(x, tau, *args)``, which
  makes its workspace per call);
* ``loop new``: the allocation-free ``plant.kernel_into`` (``rhs_into``, one workspace made before
  the loop) called inside a compiled numba loop: what a compiled closed loop pays;
* ``loop P``: the same through ``rhs_into_packed(x, tau, P, status, ws, dx)``, the plant's arrays
  passed as one tuple ``P`` (a caller compiled with numba's reference counting pays an atomic
  increment and decrement for each array it takes out of a tuple, on every call; ``loop new`` takes
  the 14 arrays out of its tuple as ``coopctrl.loop.kernel`` does today);
* ``loop old``: the right-hand side as it was before the workspace (``tests/_rhs_reference.py``,
  a dozen ``np.empty`` per call) in the same compiled loop;
* ``new/old``: their ratio, and ``RK4``: four in-loop evaluations (one RK4 step of the plant).

The in-loop figures are medians over ``--repeats`` rounds, new and old interleaved in each round,
each round the median over chunks of 25 calls timed one by one (``--calls`` calls in all), minus the
call into the loop; the Python figures are medians of individually timed calls (docs/performance.md: runs agree only to
~1.5x, so compare ratios measured in one run). Target (issue 10): <= 3 us per right-hand side in
the loop for the two-Puma carry. MuJoCo's per-step figures are printed for scale: MuJoCo 4.0, plant only
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
sys.path.insert(0, os.path.join(ROOT, "tests"))

#: MuJoCo 4.0, two 6-DOF arms holding a welded object, plant only, 1 ms step: medians [us per step] on a
#: quiet 2-core machine of this class, measured on 2026-12-01 (docs/performance.md).
MUJOCO_US_PER_STEP = {"Euler": 6.2, "implicitfast": 6.8, "RK4": 24.0}
#: The scene the target is stated for, listed first.
CARRY = "spatial_two_puma_carry"
#: Scenes of a --quick run (one per kind of plant).
QUICK_SCENES = (CARRY, "planar_two_arm_lift", "contact_points_only", "two_panda_carry")
#: Calls per individually timed chunk of the compiled loop.
CHUNK = 25
#: Target of issue 10 [us]: one right-hand side of the two-Puma carry inside a compiled loop.
TARGET_US = 3.0


def median_us(fn, calls):
    times = np.empty(calls)
    clock = time.perf_counter
    for i in range(calls):
        t0 = clock()
        fn()
        times[i] = clock() - t0
    return float(np.median(times)) * 1e6


def chunked_us(run, chunks):
    """Median cost [us] of one call inside the compiled loop ``run(reps)``: ``chunks`` chunks of
    ``CHUNK`` calls each timed on its own, minus the cost of ``run(0)`` (the call into the loop),
    so that a chunk the scheduler interrupted does not move the median (as for the Python calls)."""
    clock = time.perf_counter
    empty = np.empty(chunks)
    times = np.empty(chunks)
    for i in range(chunks):
        t0 = clock()
        run(0)
        t1 = clock()
        run(CHUNK)
        t2 = clock()
        empty[i] = t1 - t0
        times[i] = t2 - t1
    return float(np.median(times) - np.median(empty)) / CHUNK * 1e6


def _loops():
    from numba import njit

    @njit
    def loop_new(fn, x, tau, args, ws, dx, reps):
        for _ in range(reps):
            fn(x, tau, *args, ws, dx)
        return dx[0]

    @njit
    def loop_packed(fn, x, tau, P, status, ws, dx, reps):
        for _ in range(reps):
            fn(x, tau, P, status, ws, dx)
        return dx[0]

    @njit
    def loop_old(fn, x, tau, args, reps):
        s = 0.0
        for _ in range(reps):
            s += fn(x, tau, *args)[0]
        return s

    return loop_new, loop_packed, loop_old


def scene_names(quick):
    names = sorted(os.path.splitext(os.path.basename(p))[0] for p in glob.glob(os.path.join(ROOT, "scenarios", "*.toml")))
    if quick:
        names = [n for n in QUICK_SCENES if n in names]
    return [CARRY] + [n for n in names if n != CARRY]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=20000,
                    help="calls per timed chunk in the loop, and individually timed Python calls (default 20000)")
    ap.add_argument("--repeats", type=int, default=9, help="rounds of the in-loop timing (default 9)")
    ap.add_argument("--quick", action="store_true", help="2000 calls, 3 rounds, four scenes (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.calls = min(args.calls, 2000)
        args.repeats = min(args.repeats, 3)
    print(f"command: {' '.join(['python', *sys.argv])}")
    print(f"machine: {platform.machine()} {platform.processor() or ''} python {platform.python_version()} "
          f"numpy {np.__version__}, {os.cpu_count()} cpus, load average {os.getloadavg()[0]:.2f}")
    t0 = time.perf_counter()
    import _rhs_reference as ref
    from coopctrl import load_scenario

    loop_new, loop_packed, loop_old = _loops()
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
        fn, extra = plant.kernel
        fn_into, _ = plant.kernel_into
        fn_packed = sys.modules[fn_into.py_func.__module__].rhs_into_packed
        P, status = plant.plant_args, extra[-1]
        old = ref.spatial_rhs_old if plant.space == "spatial" else ref.planar_rhs_old
        ws, dx = plant.workspace(), np.empty_like(x)
        # warm: compile (or load from the numba cache) before timing; check new == old here too
        want = old(x, tau, *extra)
        fn_into(x, tau, *extra, ws, dx)
        assert extra[-1][0] == 0, (name, extra[-1])
        assert np.max(np.abs(dx - want)) <= 1e-14 * max(1.0, np.max(np.abs(want))), name
        loop_new(fn_into, x, tau, extra, ws, dx, 2)
        loop_packed(fn_packed, x, tau, P, status, ws, dx, 2)
        loop_old(old, x, tau, extra, 2)
        for _ in range(200):
            plant.rhs(0.0, x, tau)
            fn(x, tau, *extra)
        rhs_us = median_us(lambda: plant.rhs(0.0, x, tau), args.calls)
        raw_us = median_us(lambda: fn(x, tau, *extra), args.calls)
        new_t, packed_t, old_t = [], [], []
        chunks = max(1, args.calls // CHUNK)
        run_new = lambda r: loop_new(fn_into, x, tau, extra, ws, dx, r)  # noqa: E731
        run_packed = lambda r: loop_packed(fn_packed, x, tau, P, status, ws, dx, r)  # noqa: E731
        run_old = lambda r: loop_old(old, x, tau, extra, r)  # noqa: E731
        for _ in range(args.repeats):
            new_t.append(chunked_us(run_new, chunks))
            packed_t.append(chunked_us(run_packed, chunks))
            old_t.append(chunked_us(run_old, chunks))
        rows.append((name, plant.state_size, rhs_us, raw_us, float(np.median(new_t)), float(np.median(packed_t)),
                     float(np.median(old_t))))
    print(f"set-up and warm-up (scenes, numba compile or cache): {time.perf_counter() - t0:.1f} s; "
          f"{args.calls} calls per figure, in-loop medians over {args.repeats} rounds\n")
    print(f"{'scene':32s} {'states':>6s} {'python':>8s} {'kernel':>8s} {'loop new':>9s} {'loop P':>8s} {'loop old':>9s} "
          f"{'new/old':>8s} {'RK4 new':>8s}   [us per right-hand side]")
    for name, n, r, k, new, packed, old in rows:
        print(f"{name:32s} {n:6d} {r:8.2f} {k:8.2f} {new:9.2f} {packed:8.2f} {old:9.2f} {new / old:8.2f} {4 * new:8.2f}")
    carry = rows[0]
    verdict = "PASS" if carry[4] <= TARGET_US else "MISS"
    print(f"\n{CARRY}: {carry[4]:.2f} us per right-hand side in a compiled loop (target <= {TARGET_US:.0f} us: "
          f"{verdict}); {carry[5]:.2f} us with the arrays passed as one tuple; {carry[6]:.2f} us before the workspace "
          f"(ratio {carry[4] / carry[6]:.2f}); {carry[2]:.2f} us from Python")
    print("\nMuJoCo 4.0 for scale (two 6-DOF arms + welded object, plant only, per 1 ms step):")
    for mname, us in MUJOCO_US_PER_STEP.items():
        evals = 4 if mname == "RK4" else 1
        print(f"  {mname:13s} {us:5.1f} us/step | the carry's in-loop rhs evaluations of one such step "
              f"({evals}): {evals * carry[4]:6.2f} us | MuJoCo/ours {us / (evals * carry[4]):4.1f}x")
    print("(MuJoCo figures: docs/performance.md, medians measured on 2026-12-01 on a 2-core machine of the same class,"
          " not in this run: compare orders of magnitude only.)")


if __name__ == "__main__":
    main()
