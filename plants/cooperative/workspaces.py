"""The cooperative plant's preallocated workspaces (``CooperativePlant.workspace`` and ``control_workspace``),
made in Python: zero-filled float64 arrays in the namedtuples the plant's numba kernels take
(:class:`plants.cooperative._spatial_kernel.SpatialWorkspace`, ``SpatialControlWorkspace``, and their planar
twins; their docstrings list the fields), with the shapes the kernels' own ``make_workspace`` gives them.

Kept for the numba code that still calls it: coopctrl/'s numba integrators (CooperativePlant.workspace). It goes
with its last caller (tests/test_plants_without_numba.py lists it).
"""

from __future__ import annotations

import numpy as np

from plants.arms._chain_kernels import CHAIN_WORK_WIDTH
from plants.arms._planar_kernels import PLANAR_WORK_WIDTH
from plants.cooperative._planar_kernel import PlanarControlWorkspace, PlanarWorkspace
from plants.cooperative._spatial_kernel import SpatialControlWorkspace, SpatialWorkspace
from plants.elastic._spatial_kernels import EDGE_SCRATCH_SHAPE, NODE_FRAME_BLOCKS


def _largest_dof(arm_dof, p: int) -> int:
    """``n``: the largest arm dof, at least the pose size ``p``."""
    return max([p, *(int(d) for d in arm_dof)])


def new_workspace(space: str, arm_dof, node_count: int):
    """A new zero-filled workspace of the plant's right-hand side for arms of ``arm_dof`` (m,) dofs and
    ``node_count`` = m + 1 nodes: a ``SpatialWorkspace`` (``space == "spatial"``) or a ``PlanarWorkspace``."""
    m, N = len(arm_dof), int(node_count)
    if space == "spatial":
        n = _largest_dof(arm_dof, 6)
        return SpatialWorkspace(
            np.zeros((N, 6)), np.zeros((N, 6)), np.zeros((m, n, n)), np.zeros((m, n)),
            np.zeros((m, 6, n)), np.zeros((m, 6)), np.zeros((N, 3, 3)), np.zeros((N, 6)),
            np.zeros((n, n)), np.zeros(n), np.zeros(n), np.zeros(6), np.zeros((3, n)),
            np.zeros(3), np.zeros(3),
            np.zeros((n + 1, CHAIN_WORK_WIDTH)), np.zeros(EDGE_SCRATCH_SHAPE), np.zeros((N, NODE_FRAME_BLOCKS, 3, 3)),
        )
    n = _largest_dof(arm_dof, 3)
    return PlanarWorkspace(
        np.zeros((N, 3)), np.zeros((N, 3)), np.zeros((m, n, n)), np.zeros((m, n)),
        np.zeros((m, 3, n)), np.zeros((m, 3)), np.zeros((N, 3)),
        np.zeros((n, n)), np.zeros(n), np.zeros(n), np.zeros((n + 1, PLANAR_WORK_WIDTH)),
    )


def new_control_workspace(space: str, arm_dof, node_count: int):
    """A new zero-filled workspace of the plant's control terms: a ``SpatialControlWorkspace`` or a
    ``PlanarControlWorkspace`` holding a :func:`new_workspace` of its own."""
    m, N = len(arm_dof), int(node_count)
    ws = new_workspace(space, arm_dof, N)
    if space == "spatial":
        return SpatialControlWorkspace(ws, np.zeros((N, 6, 6)), np.zeros((N, 6)), np.zeros((N, 6)), np.zeros((m, 6)),
                                       np.zeros((N, 6)))
    return PlanarControlWorkspace(ws, np.zeros((N, 3, 3)), np.zeros((N, 3)), np.zeros((N, 3)), np.zeros((m, 3)),
                                  np.zeros((N, 3)))
