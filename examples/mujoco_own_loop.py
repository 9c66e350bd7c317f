"""Your own control loop: coopctrl's controller driving MuJoCo stepped by hand, the shape of a 1 kHz robot driver.

Run from the repository root (needs ``pip install 'coopctrl[mujoco]'``)::

    python examples/mujoco_own_loop.py [SCENE] [--duration 2.5]

Every control period ``T`` (1 ms in the shipped scenes) the loop does what a robot driver does:

1. read the sensors: joint positions and rates, the wrist force-torque sensors (the grasp wrenches), the
   object's pose and rate (from a tracker);
2. ask the controller for the torques: ``controller.step(t, measurement)``;
3. send the torques and let the robot run one period: here MuJoCo, stepped by hand with the torques held
   (``MujocoPlant.advance``, several MuJoCo steps with the scene's grasp elements applied).

On a robot, step 3 is the driver's write and wait for the next cycle; the rest stays as it is.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np


def own_loop(scenario, duration: float):
    """Run ``scenario``'s controller against MuJoCo for ``duration`` [s], one control period at a time.

    Returns ``(t, tau, object_pose)``: per period its time [s], the torques sent [N m] (every joint, arm after
    arm) and the object's pose measured at its start [m, rad]."""
    import coopctrl
    from coopctrl.mujoco.plant import MujocoPlant
    from coopctrl.scenario.build import initial_state

    T = scenario.simulation.control_period  # [s]
    controller = coopctrl.Controller(scenario)
    robot = MujocoPlant(scenario)  # the "robot": MuJoCo's arms and object, the scene's grasps
    robot.set_state(initial_state(scenario))  # start where `coopctrl run` starts (simulation.start)
    ticks = int(round(duration / T)) + 1
    times, taus, poses = [], [], []
    for k in range(ticks):
        t = k * T
        measurement = coopctrl.Measurement(**robot.readings())  # 1. read the sensors
        torques = controller.step(t, measurement)               # 2. the controller's torques [N m]
        robot.advance(torques.tau, T)                           # 3. send them; the robot runs one period
        times.append(t)
        taus.append(np.array(torques.tau))
        poses.append(measurement.object_pose.copy())
    return np.array(times), np.array(taus), np.array(poses)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="coopctrl's controller against MuJoCo stepped by hand")
    parser.add_argument("scene", nargs="?", default="two_panda_carry", help="a shipped scene or a .toml file")
    parser.add_argument("--duration", type=float, default=2.5, help="simulated time [s]")
    args = parser.parse_args(argv)

    import coopctrl
    from coopctrl.scenario.build import trajectory

    if not hasattr(coopctrl, "Controller"):
        print("this example needs coopctrl.Controller (the step API, docs/controller.md); update coopctrl",
              file=sys.stderr)
        return 2
    scenario = coopctrl.load_scenario(args.scene)
    wall = time.perf_counter()
    t, tau, poses = own_loop(scenario, args.duration)
    wall = time.perf_counter() - wall
    npos = 3 if poses.shape[1] == 6 else 2
    nominal = trajectory(scenario)
    errors = np.array([np.linalg.norm(pose[:npos] - np.asarray(nominal.evaluate(float(tk))[0])[:npos])
                       for tk, pose in zip(t, poses)])
    print(f"{scenario.name}: {len(t)} periods of {scenario.simulation.control_period * 1e3:g} ms in {wall:.2f} s "
          f"({args.duration / wall:.2f}x real time); object position error RMS {np.sqrt(np.mean(errors ** 2)) * 1e3:.4f} mm, "
          f"max {errors.max() * 1e3:.4f} mm; largest torque {np.max(np.abs(tau)):.4g} N m")
    return 0


if __name__ == "__main__":
    sys.exit(main())
