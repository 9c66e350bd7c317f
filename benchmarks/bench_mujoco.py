"""Benchmark: a whole ``--plant mujoco`` run against MuJoCo stepping the same model with zero torques.

Run from the repository root (needs ``pip install 'coopctrl[mujoco]'``)::

    python benchmarks/bench_mujoco.py [--scenes two_panda_carry ...] [--repeats 5] [--duration 1.0]

Per scene, alternated in each of ``--repeats`` rounds, medians over rounds, real-time factors
(simulated time / wall time, higher is faster):

* ``run``: ``simulate(scenario, plant="mujoco")``: the compiled loop (sensing, QP, controllers) with MuJoCo
  as its plant, wall time without start-up (the summary's ``realtime_factor``);
* ``own loop``: ``coopctrl.Controller`` stepped from a plain Python loop against the same MuJoCo plant, as
  ``examples/mujoco_own_loop.py`` (one ``readings()``, ``step`` and ``advance`` per control period);
* ``plant``: :class:`~coopctrl.mujoco.plant.MujocoPlant` advanced over the same duration with zero torques:
  MuJoCo's steps with the grasp wrenches applied each step (what the run's plant costs);
* ``mj_step``: bare ``mujoco.mj_step`` of the same compiled model with zero torques and no grasp wrenches.

``loop share`` is the part of the run's wall time that is not the plant's: ``1 - plant time / run time``
(the controller, the loop's sensing and the state map). Timings on a shared machine agree only to ~1.5x
between runs (docs/performance.md): compare the ratios of one run.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

SCENES = ("two_panda_carry", "ur5e_panda_carry", "three_iiwa_tray", "spatial_two_puma_carry", "planar_two_arm_lift")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", nargs="+", default=["two_panda_carry", "planar_two_arm_lift"], choices=SCENES,
                        metavar="NAME")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--duration", type=float, default=1.0, help="simulated time per run [s]")
    parser.add_argument("--quick", action="store_true", help="one repeat of 0.1 s on the planar lift (a smoke run)")
    args = parser.parse_args(argv)
    if args.quick:
        args.scenes, args.repeats, args.duration = ["planar_two_arm_lift"], 1, 0.1
    if args.repeats < 1 or not args.duration > 0:
        parser.error("--repeats must be >= 1 and --duration > 0")
    import mujoco

    import coopctrl
    from coopctrl.mujoco.plant import MujocoPlant
    from coopctrl.scenario import load_scenario
    from coopctrl.scenario.build import initial_state
    from coopctrl.simulator import simulate

    print(f"MuJoCo {mujoco.__version__}; {args.duration:g} s simulated per run; medians of {args.repeats} rounds, "
          "alternated; real-time factors [x]")
    print(f"{'scene':26}{'run':>10}{'own loop':>10}{'plant':>10}{'mj_step':>10}{'loop share':>12}")
    for name in args.scenes:
        sc = load_scenario(name, {"simulation.duration": args.duration})
        x0 = initial_state(sc)
        mp = MujocoPlant(sc)
        simulate(sc, plant="mujoco", node_poses=False)  # loads the kernels (start-up, not timed)
        zeros = np.zeros(mp.state_map.n_q)
        steps = int(round(args.duration / mp.timestep))
        run, own, plant, bare = [], [], [], []
        T = sc.simulation.control_period
        mp.set_state(x0)
        coopctrl.Controller(sc).step(0.0, coopctrl.Measurement(**mp.readings()))  # loads the step (start-up)
        for _ in range(args.repeats):
            r = simulate(sc, plant="mujoco", node_poses=False)
            if r.status != "ok":
                print(f"{name}: the run ended {r.status}: {r.reason}", file=sys.stderr)
                return 1
            run.append(r.wall_time_s)
            controller = coopctrl.Controller(sc)
            mp.set_state(x0)
            t0 = time.perf_counter()
            for k in range(len(r.t)):
                mp.advance(controller.step(k * T, coopctrl.Measurement(**mp.readings())).tau, T)
            own.append(time.perf_counter() - t0)
            mp.set_state(x0)
            t0 = time.perf_counter()
            mp.advance(zeros, args.duration)
            plant.append(time.perf_counter() - t0)
            mp.set_state(x0)
            mp.data.xfrc_applied[:] = 0.0
            mp.data.qfrc_applied[:] = 0.0
            t0 = time.perf_counter()
            for _ in range(steps):
                mujoco.mj_step(mp.model, mp.data)
            bare.append(time.perf_counter() - t0)
        t_run, t_own, t_plant, t_bare = (float(np.median(v)) for v in (run, own, plant, bare))
        print(f"{name:26}{args.duration / t_run:>10.3g}{args.duration / t_own:>10.3g}{args.duration / t_plant:>10.3g}"
              f"{args.duration / t_bare:>10.3g}"
              f"{1.0 - t_plant / t_run:>12.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
