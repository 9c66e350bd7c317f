"""Pre-flight's compiled, warm-started inverse kinematics against the arms' own (Python) solve."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.analysis.preflight_ik import warm_ik
from plants.arms import iiwa14, planar3r, puma560
from plants.arms.puma560 import GRIPPER_TOOL


def _path(arm, q_start, dq, steps):
    """Node poses the arm passes through from ``q_start`` along ``dq`` per step: reachable by construction."""
    return [arm.terms(q_start + k * dq, np.zeros(arm.dof)).Y for k in range(1, steps + 1)]


@pytest.mark.parametrize("make, q_start, dq", [
    (lambda: puma560(tool=GRIPPER_TOOL), np.array([0.1, 0.6, -2.4, 0.2, 0.4, 0.1]), np.full(6, 0.05)),
    (lambda: planar3r(), np.array([0.6, 0.9, -0.7]), np.array([0.04, -0.03, 0.05])),
    (lambda: iiwa14(), np.array([0.1, 0.5, 0.1, -1.2, 0.1, 0.6, 0.2]), np.full(7, 0.03)),  # redundant: posture
])
def test_warm_solve_follows_the_branch_of_the_arms_own_solve(make, q_start, dq):
    """Sample after sample from the previous answer, the compiled solve gives the joints the arm's
    own solve gives from the same seed (both stop at a 1e-9 residual on the same branch: 1e-7 rad
    covers the spread of two stopping points of that residual over a few iterations)."""
    arm = make()
    solve = warm_ik(arm)
    q = q_start.copy()
    for target in _path(arm, q_start, dq, 6):
        expected = arm.inverse_kinematics(target, q, seeds=0)
        got = solve(target, q)
        assert got is not None
        assert np.allclose(got, expected, rtol=0.0, atol=1e-7), (got, expected)
        q = got


def test_an_unreachable_pose_is_not_converged():
    arm = puma560(tool=GRIPPER_TOOL)
    q = np.array([0.1, 0.6, -2.4, 0.2, 0.4, 0.1])
    seed = q.copy()
    assert warm_ik(arm)(np.array([5.0, 0.0, 0.5, 0.0, 0.0, 0.0]), q) is None  # 5 m away: beyond its reach
    assert np.array_equal(q, seed)  # the seed is not changed
