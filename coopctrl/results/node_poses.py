"""The node (end-effector) poses of a run's recorded states, in one compiled pass.

    Y_nodes[k, i] = Phi_i(q_i(t_k))   [m, rad]

for every sample ``k`` whose state ``x[k]`` is finite (``NaN`` elsewhere), each arm's node pose
(docs/model.md section 2). :func:`node_poses_of` runs the pass in the C++ core
(``coopctrl._core.spatial_node_poses``, ``planar_node_poses``, coopctrl/core/node_poses.h: the port, bit for
bit, of this module's numba kernels, which stay as the tests' reference). The pass calls the plant's own
compiled kinematics once per sample inside one loop, so the poses are bit for bit those of
:meth:`CooperativePlant.node_poses <plants.cooperative.CooperativePlant.node_poses>` at ``x[k]``, without a
Python call per sample (2501 such calls cost 30 to 60 ms on the two-Puma carry). Spatial: the forward kinematics
alone (``node_poses_into``, the same link frames and tip as ``node_state_into``, which also computes the rates
and the arm dynamics: 2.9 ms against 8.2 ms for the carry's 2501 samples, ``benchmarks/bench_node_poses.py``);
planar: ``node_state_into`` (three-link arms: the dynamics cost little).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from plants.cooperative import _planar_kernel as _pk
from plants.cooperative import _spatial_kernel as _sk


@njit(cache=True)
def _spatial_poses(X, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, status, ws, out):
    """Spatial plant: ``out[k]`` (m, 6) for each finite row ``X[k]``; returns the first row whose
    kinematics reported a nonzero ``status[0]``, or -1."""
    n, width = X.shape
    m, p = out.shape[1], out.shape[2]
    for k in range(n):
        finite = True
        for j in range(width):
            if not np.isfinite(X[k, j]):
                finite = False
                break
        if not finite:
            continue
        _sk.node_poses_into(X[k], arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, status, ws)
        if status[0] != 0:
            return k
        for i in range(m):
            for a in range(p):
                out[k, i, a] = ws.Y[i + 1, a]
    return -1


@njit(cache=True)
def _planar_poses(X, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status, ws, out):
    """Planar plant: as :func:`_spatial_poses`, ``out[k]`` (m, 3)."""
    n, width = X.shape
    m, p = out.shape[1], out.shape[2]
    for k in range(n):
        finite = True
        for j in range(width):
            if not np.isfinite(X[k, j]):
                finite = False
                break
        if not finite:
            continue
        _pk.node_state_into(X[k], arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status, ws)
        if status[0] != 0:
            return k
        for i in range(m):
            for a in range(p):
                out[k, i, a] = ws.Y[i + 1, a]
    return -1


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
