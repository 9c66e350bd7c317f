"""The node (end-effector) poses of a run's recorded states, in one compiled pass.

    Y_nodes[k, i] = Phi_i(q_i(t_k))   [m, rad]

for every sample ``k`` whose state ``x[k]`` is finite (``NaN`` elsewhere), each arm's node pose
(docs/model.md section 2). :func:`node_poses_of` runs the pass in the C++ core
(``coopctrl._core.spatial_node_poses``, ``planar_node_poses``, coopctrl/core/node_poses.h). The pass calls the
plant's own compiled kinematics once per sample inside one loop, so the poses are bit for bit those of
:meth:`CooperativePlant.node_poses <plants.cooperative.CooperativePlant.node_poses>` at ``x[k]``, without a
Python call per sample (2501 such calls cost 30 to 60 ms on the two-Puma carry). Spatial: the forward kinematics
alone (the same link frames and tip as the node state, which also computes the rates and the arm dynamics;
``benchmarks/bench_node_poses.py``); planar: the node state (three-link arms: the dynamics cost little).
"""

from __future__ import annotations

import numpy as np


def node_poses_of(x: np.ndarray, plant) -> np.ndarray:
    """``Y_nodes`` (N, m, p) [m, rad] of the states ``x`` (N, state_size) of ``plant`` (a
    :class:`~plants.cooperative.CooperativePlant`): ``NaN`` rows where ``x[k]`` is not finite.

    Raises what ``plant.node_poses(x[k])`` raises at the first sample whose kinematics fail (an Euler
    singularity of a node)."""
    x = np.ascontiguousarray(x, dtype=float)
    n, m, p = x.shape[0], plant.arm_count, plant.p
    out = np.full((n, m, p), np.nan)
    if n == 0:
        return out
    from coopctrl._core import planar_node_poses, spatial_node_poses

    status = np.zeros(2, dtype=np.int64)
    poses = spatial_node_poses if plant.space == "spatial" else planar_node_poses
    bad = poses(x, plant.plant_args, status, out)
    if bad >= 0:
        plant.node_poses(x[bad])  # the plant's own check raises its error
        raise RuntimeError(f"node kinematics failed at sample {bad} (status {int(status[0])})")  # not reached
    return out
