"""A run's node poses (``Y_nodes``): the forward-kinematics pass beside the whole node-state pass.

Run: python benchmarks/bench_node_poses.py [--repeats N] [--scenes a,b] [--quick]

``simulate()`` ends with each recorded state's node poses (:func:`coopctrl.results.node_poses.node_poses_of`).
For a spatial scene that pass runs the arms' forward kinematics alone (``node_poses_into``); before, it ran the
plant's whole ``node_state_into`` per sample (the node rates and every arm's dynamics and Jacobian too). Per
spatial scene, on the states of one recorded run, both passes are timed ``repeats`` times alternately (the
whole-state pass is compiled here, as the results module compiled it before); the medians, their ratio and
whether the poses are equal bit for bit are printed.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from numba import njit

import coopctrl
from coopctrl.results.node_poses import node_poses_of
from coopctrl.simulator import closed_loop, run_result
from plants.cooperative import _spatial_kernel as _sk

from _scene_options import add_scene_options, chosen_scenarios

SCENES = ("spatial_two_puma_carry", "ur5e_panda_carry", "three_iiwa_tray")


@njit(cache=True)
def _node_state_pass(X, arm_kind, arm_dof, q_off, tables, table_off, bases, tools, gravity, status, ws, out):
    """The pass as it was: the plant's whole node state per sample, then its poses."""
    m, p = out.shape[1], out.shape[2]
    for k in range(X.shape[0]):
        _sk.node_state_into(X[k], arm_kind, arm_dof, q_off, tables, table_off, bases, tools, gravity, status, ws)
        for i in range(m):
            for a in range(p):
                out[k, i, a] = ws.Y[i + 1, a]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_scene_options(parser, 15, "timed passes of each kind per scene",
                      f"comma-separated spatial scenes (default: {','.join(SCENES)})")
    args = parser.parse_args(argv)
    scenarios = chosen_scenarios(parser, args, SCENES)  # every scene checked before any work
    for name, scenario in scenarios.items():
        if scenario.space != "spatial":
            parser.error(f"--scenes {name}: a spatial scene is expected (the planar pass is unchanged)")
    print(f"command: {' '.join([Path(sys.executable).name, *sys.argv])}; coopctrl from {Path(coopctrl.__file__).parent}")
    print(f"{'scene':26s} {'samples':>7s} {'node state ms':>13s} {'kinematics ms':>13s} {'ratio':>6s} bit-identical")
    for name, scenario in scenarios.items():
        loop = closed_loop(scenario)
        x = np.ascontiguousarray(run_result(scenario, loop).x)
        x = x[np.all(np.isfinite(x), axis=1)]
        plant, P = loop.plant, loop.plant.plant_args

        def whole_state():
            out = np.full((x.shape[0], plant.arm_count, plant.p), np.nan)
            _node_state_pass(x, P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases, P.tools, P.gravity,
                             np.zeros(2, dtype=np.int64), plant.workspace(), out)
            return out

        same = np.array_equal(whole_state(), node_poses_of(x, plant))
        walls = {"state": [], "poses": []}
        for _ in range(args.repeats):
            for key, call in (("state", whole_state), ("poses", lambda: node_poses_of(x, plant))):
                t0 = time.perf_counter()
                call()
                walls[key].append(time.perf_counter() - t0)
        before, after = statistics.median(walls["state"]), statistics.median(walls["poses"])
        print(f"{name:26s} {x.shape[0]:7d} {before * 1e3:13.2f} {after * 1e3:13.2f} {after / before:6.3f} {same}",
              flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
