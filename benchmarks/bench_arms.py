"""Benchmark: one Puma 560 evaluation of the arm's terms (H, h, J, dJ dq, the tip pose) vs Pinocchio.

Run from the repository root::

    python benchmarks/bench_arms.py [--calls 20000] [--quick]

Prints the median time of one warm ``SerialArm.terms`` call from Python (the DH kernel in the compiled core,
plants/core/dh_arm.h), the same for ``ChainArm.terms`` (plants/core/chain_arm.h: the Panda, UR5e and iiwa 14
from their URDF files), and Pinocchio's
``crba + nonLinearEffects + computeFrameJacobian`` (+ the frame placement) for the same
configuration from Python, with their ratio. Both sides pay a Python call; inside the tick the arm's terms
cost what ``benchmarks/bench_plant.py``'s in-core right-hand side shows. Medians over repeated calls
(docs/performance.md: runs agree only to ~1.5x, compare ratios from one run).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from plants.arms import iiwa14, panda, puma560, ur5e  # noqa: E402


def chain_rows(calls: int):
    """us per ``ChainArm.terms`` call from Python on the URDF arms."""
    rows = []
    for label, arm in (("Panda (URDF)", panda()), ("UR5e (URDF)", ur5e()), ("iiwa 14 (URDF)", iiwa14())):
        n = arm.dof
        rng = np.random.default_rng(0)
        lo, hi = np.maximum(arm.q_limits[:, 0], -np.pi), np.minimum(arm.q_limits[:, 1], np.pi)
        q, dq = rng.uniform(lo, hi), rng.uniform(-2.0, 2.0, n)
        arm.terms(q, dq)
        rows.append((label, n, median_us(lambda: arm.terms(q, dq), calls)))
    return rows


def median_us(fn, repeats=2000):
    times = np.empty(repeats)
    for i in range(repeats):
        t0 = time.perf_counter()
        fn()
        times[i] = time.perf_counter() - t0
    return float(np.median(times)) * 1e6


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--calls", type=int, default=20000, help="individually timed calls per measurement (default 20000)")
    ap.add_argument("--quick", action="store_true", help="2000 timed calls (a smoke run)")
    args = ap.parse_args(argv)
    calls = min(args.calls, 2000) if args.quick else args.calls
    arm = puma560()
    rng = np.random.default_rng(0)
    q = rng.uniform(arm.q_limits[:, 0], arm.q_limits[:, 1])
    dq = rng.uniform(-2.0, 2.0, 6)
    dh = arm.dh_array()
    arm.terms(q, dq)  # warm up
    ours = median_us(lambda: arm.terms(q, dq), calls)

    print(f"command: {sys.executable} {' '.join(sys.argv)}")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, python {platform.python_version()}")
    print(f"SerialArm.terms (Puma 560, DH), from Python      : {ours:8.2f} us  (median)")
    print("ChainArm.terms (general joints), from Python, per arm evaluation:")
    for label, n, py in chain_rows(calls):
        print(f"  {label:24s} n={n}: {py:8.2f} us")
    try:
        import pinocchio as pin
    except ImportError:
        print("pinocchio not installed: no baseline")
        return
    # Pinocchio model built from the same DH table (as in tests/test_arms.py).
    model = pin.Model()
    parent, placement = 0, pin.SE3.Identity()
    for k, row in enumerate(dh):
        joint = model.addJoint(parent, pin.JointModelRZ(), placement, f"j{k}")
        P = pin.SE3(pin.utils.rotate("z", row[3]), np.zeros(3)) * pin.SE3(np.eye(3), np.array([0, 0, row[2]])) * pin.SE3(
            pin.utils.rotate("x", row[1]), np.array([row[0], 0, 0])
        )
        link = arm.links[k]
        model.appendBodyToJoint(joint, P.act(pin.Inertia(link.mass, np.array(link.rc), link.inertia_matrix())), pin.SE3.Identity())
        parent, placement = joint, P
    frame = model.addFrame(pin.Frame("tool", parent, placement, pin.FrameType.OP_FRAME))
    data = model.createData()
    world = pin.LOCAL_WORLD_ALIGNED

    def pinocchio_terms():
        pin.crba(model, data, q)
        pin.nonLinearEffects(model, data, q, dq)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        pin.getFrameJacobian(model, data, frame, world)

    pinocchio_terms()
    theirs = median_us(pinocchio_terms, calls)
    print(f"pinocchio crba+nle+jacobian+placement, Python   : {theirs:8.2f} us  (median)")
    print(f"ratio pinocchio / ours (both from Python)       : {theirs / ours:8.2f}")


if __name__ == "__main__":
    main()
