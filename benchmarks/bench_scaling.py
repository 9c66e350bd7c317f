"""Cost per step as the number of arms m grows from 2 to 8 (Pumas in a ring around one object).

Run from the repository root::

    python benchmarks/bench_scaling.py [--repeats 3] [--quick] [--calls 20000]

For each m a scenario is built programmatically (``scenario_from_dict``): m Puma 560 arms on a
circle of radius 0.7 m around a 2 kg box, each gripping it 0.15 m from its centre and facing it
(the ring of ``tests/_scenes.py scene(m=...)``, arm 1 the leader), one offset spring per arm
as in spatial_two_puma_carry, a lift of 0.2 m with a 0.2 rad turn about z in 2 s. Per m it
prints, measured side by side in one process (the m are interleaved round by round):

* ``rhs``: one evaluation of the plant's right-hand side [us] (median of individually timed
  calls at the loaded initial state);
* ``RK4 step``: one RK4 integration step of the plant [us] (four evaluations plus the vector
  arithmetic), the **cost per step** of the issue's target;
* ``tick``: one whole closed-loop control period [us] (sensors, QP with 6m variables, leader,
  m - 1 follower force loops, one RK4 step), median over ``--repeats`` runs;

and each as ``time(m) / time(2)``. Target: close to linear in m, ``time(8) / time(2) <= 4.5``
(linear would be 4.0). The PASS/FAIL verdict is printed per column; the target is stated for
the cost per integration step (the RK4 column); the tick is shown for what a user waits for.
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

from coopctrl.integrators import get_integrator  # noqa: E402
from coopctrl.scenario.loader import scenario_from_dict  # noqa: E402
from coopctrl.simulator import simulate  # noqa: E402

ARMS = (2, 3, 4, 5, 6, 7, 8)
#: Target on time(8) / time(2) of the cost per step [-] (linear would be 4).
TARGET = 4.5


def ring_scenario(m: int, duration: float):
    """m Pumas in a ring around a 2 kg box (see the module docstring)."""
    arms, springs = [], []
    for k in range(m):
        phi = math.pi + 2.0 * math.pi * k / m  # where arm k stands, seen from the object
        yaw = math.remainder(phi + math.pi, 2.0 * math.pi)  # the node faces the object
        c, s = math.cos(phi), math.sin(phi)
        arms.append({"model": "puma560", "role": "leader" if k == 0 else "follower",
                     "base": [0.7 * c, 0.7 * s, 0.0, yaw, 0.0, 0.0], "grasp": [0.15 * c, 0.15 * s, 0.0, yaw, 0.0, 0.0],
                     "node_mass": 0.3, "node_inertia": [1e-3, 1.2e-3, 1.4e-3]})
        springs.append({"pair": [0, k + 1], "stiffness": 2e4, "torsion": 200.0, "damping": 60.0,
                        "torsion_damping": 0.5, "element": "offset"})
    start = [0.0, 0.0, 0.45, 0.0, 0.0, 0.0]
    return scenario_from_dict({
        "name": f"ring_of_{m}_pumas",
        "scene": {"space": "spatial", "unloaded_state": "mobile", "gravity": 9.81},
        "object": {"mass": 2.0, "inertia": [0.02, 0.025, 0.03], "pose": start},
        "arms": arms, "springs": springs,
        "trajectory": {"via": [{"time": 0.0, "pose": start}, {"time": 2.0, "pose": [0.0, 0.0, 0.65, 0.2, 0.0, 0.0]}]},
        "load_distribution": {"split": "pseudo_inverse", "squeeze": 10.0},
        "controllers": {"leader": {"natural_frequency": 40.0, "damping_ratio": 1.0},
                        "followers": {"force_loop": True, "force_kp": 1.0, "force_ki": 40.0,
                                      "natural_frequency": 60.0, "damping_ratio": 1.0}},
        "simulation": {"duration": duration, "control_period": 0.001, "integrator": "rk4", "substeps": 1},
    })


def interleaved_us(fns, calls: int, rounds: int = 10) -> list[float]:
    """Median [us] of individually timed calls of each fn, interleaved in ``rounds`` rounds."""
    per_round = max(1, calls // rounds)
    samples = [[] for _ in fns]
    clock = time.perf_counter
    for _ in range(rounds):
        for k, fn in enumerate(fns):
            out = samples[k]
            for _ in range(per_round):
                t0 = clock()
                fn()
                out.append(clock() - t0)
    return [float(np.median(s)) * 1e6 for s in samples]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3, help="closed-loop runs per m (default 3)")
    parser.add_argument("--calls", type=int, default=20000, help="timed rhs and RK4-step calls per m (default 20000)")
    parser.add_argument("--quick", action="store_true", help="1 closed-loop run of 0.2 s per m, 2000 calls")
    args = parser.parse_args(argv)
    repeats = 1 if args.quick else args.repeats
    calls = 2000 if args.quick else args.calls
    duration = 0.2 if args.quick else 0.5
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}")
    print(f"machine: {platform.machine()} python {platform.python_version()} numpy {np.__version__}, "
          f"{os.cpu_count()} cpus (load average {os.getloadavg()[0]:.1f}); closed loop: {duration} s simulated per run, median of {repeats} run(s); "
          f"{calls} timed calls per m for rhs and RK4 step")
    t0 = time.perf_counter()
    scenarios = [ring_scenario(m, duration) for m in ARMS]
    rk4 = get_integrator("rk4")
    rhs_fns, step_fns, sizes = [], [], []
    for s in scenarios:
        plant, x0 = s.plant(), np.ascontiguousarray(s.initial_state())
        tau = np.zeros(plant.input_size)
        h = s.simulation.step
        plant.rhs(0.0, x0, tau)
        rhs_fns.append(lambda plant=plant, x0=x0, tau=tau: plant.rhs(0.0, x0, tau))
        step_fns.append(lambda plant=plant, x0=x0, tau=tau, h=h: rk4.step(plant.rhs, 0.0, x0, tau, h))
        sizes.append(plant.state_size)
    rhs_us = interleaved_us(rhs_fns, calls)
    step_us = interleaved_us(step_fns, calls)
    for s in scenarios:  # warm-up of the closed loop (numba cache, QP set-up)
        simulate(ring_scenario(len(s.arms), 0.01))
    ticks = [[] for _ in scenarios]
    qp = [[] for _ in scenarios]
    status = [None] * len(scenarios)
    for _ in range(repeats):
        for k, s in enumerate(scenarios):
            r = simulate(s)
            ticks[k].append(r.wall_time_s / max(1, len(r.t)) * 1e6)
            qp[k].append(r.summary()["qp_solve_time_median_us"] or float("nan"))
            status[k] = status[k] or r.status
    tick_us = [statistics.median(v) for v in ticks]
    qp_us = [statistics.median(v) for v in qp]
    print(f"set-up and measurements took {time.perf_counter() - t0:.1f} s\n")
    print(f"{'m':>2s} {'states':>6s} {'rhs [us]':>9s} {'/ m=2':>6s} {'RK4 step [us]':>14s} {'/ m=2':>6s} "
          f"{'tick [us]':>10s} {'/ m=2':>6s} {'(QP [us]':>9s} {'/ m=2)':>7s} {'m/2':>5s}  run")
    for k, m in enumerate(ARMS):
        print(f"{m:2d} {sizes[k]:6d} {rhs_us[k]:9.2f} {rhs_us[k] / rhs_us[0]:6.2f} {step_us[k]:14.2f} "
              f"{step_us[k] / step_us[0]:6.2f} {tick_us[k]:10.1f} {tick_us[k] / tick_us[0]:6.2f} {qp_us[k]:9.1f} "
              f"{qp_us[k] / qp_us[0]:7.2f} {m / 2:5.1f}  {status[k]}")
    print(f"\ntarget: time(m=8) / time(m=2) <= {TARGET} (linear: 4.0), for the cost per integration step:")
    for label, values in (("RK4 step (the target's cost per step)", step_us), ("rhs evaluation", rhs_us),
                          ("closed-loop tick (shown, not the target)", tick_us)):
        ratio = values[-1] / values[0]
        print(f"  {label:42s} {ratio:5.2f}  {'PASS' if ratio <= TARGET else 'FAIL'}")
    print("\nleast-squares line time = a + b m (a: the part that does not grow with m, such as Python call "
          "overhead; b: the cost per arm) and the largest deviation of a measurement from it:")
    for label, values in (("RK4 step", step_us), ("rhs evaluation", rhs_us), ("closed-loop tick", tick_us)):
        b, a = np.polyfit(ARMS, values, 1)
        dev = max(abs(v - (a + b * m)) / v for v, m in zip(values, ARMS))
        print(f"  {label:18s} a = {a:7.2f} us, b = {b:6.2f} us per arm, largest deviation {dev * 100:4.1f} %")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
