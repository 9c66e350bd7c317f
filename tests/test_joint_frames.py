"""plants/arms/joint_frames.py: the drawn links end at the arm's node frame (forward kinematics
recomputed in numpy must agree with the kernels')."""

from __future__ import annotations

import numpy as np
import pytest

from plants.arms import planar3r, puma560
from plants.arms.joint_frames import arm_polyline
from plants.arms.puma560 import GRIPPER_TOOL
from plants.frames import rotation_zyx


@pytest.mark.parametrize("seed", range(5))
def test_puma_polyline_ends_at_the_tip_transform(seed):
    rng = np.random.default_rng(seed)
    base = np.eye(4)
    base[:3, :3] = rotation_zyx(rng.uniform(-1, 1, 3))
    base[:3, 3] = rng.uniform(-1, 1, 3)
    arm = puma560(base=base, tool=GRIPPER_TOOL)
    q = rng.uniform(-2, 2, 6)
    pts = arm_polyline(arm, q)
    T, _ = arm.tip_transform(q)
    assert pts.shape == (14, 3)
    np.testing.assert_allclose(pts[0], base[:3, 3], atol=1e-12)
    np.testing.assert_allclose(pts[-1], T[:3, 3], atol=1e-12)  # same products, rounding only


@pytest.mark.parametrize("seed", range(5))
def test_planar_polyline_lies_in_the_plane_and_ends_at_the_node(seed):
    rng = np.random.default_rng(seed)
    arm = planar3r(base=rng.uniform(-1, 1, 3))
    q = rng.uniform(-2, 2, 3)
    pts = arm_polyline(arm, q)
    assert pts.shape == (5, 3) and np.all(pts[:, 1] == 0.0)
    np.testing.assert_allclose(pts[-1, [0, 2]], arm.pose(q)[:2], atol=1e-12)
    lengths = np.linalg.norm(np.diff(pts[:4], axis=0), axis=1)
    np.testing.assert_allclose(lengths, [link.length for link in arm.links], atol=1e-12)


def test_unknown_arm_is_left_to_the_caller():
    assert arm_polyline(object(), np.zeros(3)) is None
