"""Benchmark: one evaluation of the cooperative plant's right-hand side, from Python and inside the compiled core.

Run from the repository root::

    python benchmarks/bench_plant.py [--calls 20000] [--repeats 9] [--quick]

For the two-Puma carry and every other shipped scene (``scenarios/*.toml``, built as ``coopctrl run``
builds them, at a perturbed initial state), side by side in one run, it prints the median cost of
one right-hand side [us]:

* ``python``: ``plant.rhs(t, x, tau)`` (one call into the core with its shape checks and status check);
* ``core``: the right-hand side inside the compiled core, as the tick's integrators call it: explicit Euler
  over many steps in one call (``coopctrl._core.plant_advance``: one right-hand side and one axpy of the
  state per step), less the same call over one step, per step;
* ``RK4``: four in-core evaluations (one RK4 step of the plant).

The in-core figures are medians over ``--repeats`` rounds of chunks; the Python figures are medians of
individually timed calls (docs/performance.md: runs agree only to ~1.5x, so compare ratios measured in one run).
Target (issue 10): <= 3 us per right-hand side in the loop for the two-Puma carry. MuJoCo's per-step figures
are printed for scale: MuJoCo 4.0, plant only (two 6-DOF arms holding a welded object, no controller), 1 ms
step, medians on a quiet 2-core AMD EPYC machine of the class this project is developed on, measured on
2026-12-01: RK4 24 us per step (41x real time), Euler 6.2 us, implicitfast 6.8 us (docs/performance.md). They
are not measured by this script.
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


def core_us(plant, x, tau, chunk: int, rounds: int) -> float:
    """Median cost of one right-hand side inside the core [us]: explicit Euler over ``chunk`` steps of 1e-9 s
    (one call of ``plant_advance``), less one step, divided by ``chunk - 1``; medians over ``rounds``."""
    import coopctrl._core as _core
    from coopctrl.integrators import ExplicitEuler
    from coopctrl.integrators.compiled import make_plan

    nx = x.shape[0]
    plan = make_plan(ExplicitEuler(), nx)
    status, x_fail = np.zeros(2, np.int64), np.zeros(nx)
    report = _core.StopReport()
    many, one = np.full(chunk, 1e-9), np.full(1, 1e-9)
    per = []
    for _ in range(rounds):
        y = x.copy()
        t0 = time.perf_counter()
        _core.plant_advance(plan, y, tau, plant.plant_args, status, 0.0, one, x_fail, report)
        t1 = time.perf_counter()
        y = x.copy()
        _core.plant_advance(plan, y, tau, plant.plant_args, status, 0.0, many, x_fail, report)
        t2 = time.perf_counter()
        assert status[0] == 0, status
        per.append(((t2 - t1) - (t1 - t0)) / (chunk - 1))
    return float(np.median(per)) * 1e6


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
    from coopctrl import load_scenario

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
        for _ in range(200):
            plant.rhs(0.0, x, tau)
        rhs_us = median_us(lambda: plant.rhs(0.0, x, tau), args.calls)
        core = core_us(plant, x, tau, max(2, args.calls // 4), args.repeats)
        rows.append((name, plant.state_size, rhs_us, core))
    print(f"set-up and warm-up: {time.perf_counter() - t0:.1f} s; {args.calls} calls per Python figure, in-core "
          f"medians over {args.repeats} rounds\n")
    print(f"{'scene':32s} {'states':>6s} {'python':>8s} {'core':>8s} {'RK4 core':>9s}   [us per right-hand side]")
    for name, n, r, c in rows:
        print(f"{name:32s} {n:6d} {r:8.2f} {c:8.2f} {4 * c:9.2f}")
    carry = rows[0]
    verdict = "PASS" if carry[3] <= TARGET_US else "MISS"
    print(f"\n{CARRY}: {carry[3]:.2f} us per right-hand side in the core (target <= {TARGET_US:.0f} us: {verdict}); "
          f"{carry[2]:.2f} us from Python")
    print("\nMuJoCo 4.0 for scale (two 6-DOF arms + welded object, plant only, per 1 ms step):")
    for mname, us in MUJOCO_US_PER_STEP.items():
        evals = 4 if mname == "RK4" else 1
        print(f"  {mname:13s} {us:5.1f} us/step | the carry's in-core rhs evaluations of one such step "
              f"({evals}): {evals * carry[3]:6.2f} us | MuJoCo/ours {us / (evals * carry[3]):4.1f}x")
    print("(MuJoCo figures: docs/performance.md, medians measured on 2026-12-01 on a 2-core machine of the same class,"
          " not in this run: compare orders of magnitude only.)")


if __name__ == "__main__":
    main()
