"""Benchmark of the load-distribution QP: persistent proxsuite QP vs daqp through qpsolvers.

Spatial scenes with m = 2, 3, 4 arms and joint torque limits (6-joint arms), along a slowly
varying 1 kHz trajectory (the object turns and its load changes a little each step), so the warm
start sees what it sees in the closed loop. Prints median solve times [us] (wall clock around the
solver call: update and solve for proxsuite, problem build and solve for qpsolvers), the median
total time of one ``LoadDistribution.solve`` step (assembly included), ratios, and the command.

Run: ``python benchmarks/bench_qp.py [--steps N]``
"""

from __future__ import annotations

import argparse
import math
import pathlib
import sys

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))

from coopctrl.load_distribution import LoadDistribution, LoadDistributionConfig  # noqa: E402


def scene(m: int, steps: int, seed: int = 0):
    """Yield (r_contacts, r_object, w_N, J, bias, tau_max) along a smooth trajectory."""
    rng = np.random.default_rng(seed)
    J0 = [rng.normal(size=(6, 6)) * 0.4 for _ in range(m)]
    b0 = [rng.normal(size=6) * 2.0 for _ in range(m)]
    ang = 2 * np.pi * np.arange(m) / m
    rho = 0.3 * np.stack([np.cos(ang), np.sin(ang), np.zeros(m)], axis=1)
    mass = 8.0
    # torque limit: 70 % of the largest torque the unconstrained split needs at t = 0 (so active)
    tau_max = None
    for s in range(steps):
        t = s * 1e-3
        a = 0.5 * math.sin(2 * np.pi * 0.5 * t)
        c, sn = math.cos(a), math.sin(a)
        R = np.array([[c, -sn, 0.0], [sn, c, 0.0], [0.0, 0.0, 1.0]])
        r0 = np.array([0.1 * t, 0.0, 0.5])
        r = r0 + rho @ R.T
        w = np.array([2.0 * math.sin(3 * t), 1.0, mass * 9.81 + 5.0 * math.sin(2 * t), 0.3, -0.2, 0.5 * math.cos(t)])
        J = [Ji * (1.0 + 0.05 * math.sin(t + i)) for i, Ji in enumerate(J0)]
        if tau_max is None:
            ld = LoadDistribution(LoadDistributionConfig(), "spatial", m)
            F = ld.solve(r, r0, w).F
            tau_max = [0.7 * np.max(np.abs(J[i].T @ F[i] + b0[i])) * np.ones(6) for i in range(m)]
        yield r, r0, w, J, b0, tau_max


def run(m: int, solver: str, steps: int):
    ld = LoadDistribution(LoadDistributionConfig(torque_limits=True, solver=solver), "spatial", m)
    import time

    total, active = [], 0
    for r, r0, w, J, b, tau in scene(m, steps):
        t0 = time.perf_counter()
        s = ld.solve(r, r0, w, jacobians=J, biases=b, tau_max=tau)
        total.append(time.perf_counter() - t0)
        active += "torque_limits" in s.binding
    st = ld.statistics
    assert all(x == "solved" for x in st["status"]), set(st["status"])
    solve = np.array(st["solve_time_s"][10:]) * 1e6
    return float(np.median(solve)), float(np.median(np.array(total[10:]) * 1e6)), active / steps, st["iterations"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=2000, help="steps per case (1 ms each; default 2000)")
    ap.add_argument("--quick", action="store_true", help="300 steps per case (a smoke run)")
    args = ap.parse_args(argv)
    if args.quick:
        args.steps = min(args.steps, 300)
    print("command:", " ".join([pathlib.Path(sys.executable).name] + sys.argv))
    print(f"spatial, 6-joint arms with torque limits, {args.steps} steps of a smooth 1 kHz trajectory, eps_abs=1e-9")
    print(f"{'m':>2} | {'proxsuite solve':>15} | {'daqp solve':>10} | {'ratio':>5} | "
          f"{'proxsuite step':>14} | {'daqp step':>9} | {'ratio':>5} | {'limits active':>13} | proxsuite iters (median)")
    for m in (2, 3, 4):
        ps, pt, act, it = run(m, "proxsuite", args.steps)
        ds, dt, _, _ = run(m, "daqp", args.steps)
        print(f"{m:>2} | {ps:>12.1f} us | {ds:>7.1f} us | {ps / ds:>5.2f} | {pt:>11.1f} us | {dt:>6.1f} us | "
              f"{pt / dt:>5.2f} | {act:>12.0%} | {int(np.median(it))}")
    print("solve = wall clock around the solver call; step = one LoadDistribution.solve (assembly + solve + checks)")


if __name__ == "__main__":
    main()
