"""coopctrl/core/control_laws (coopctrl._core): the same numbers as the numba laws the loop runs today
(coopctrl.controllers.laws), bit for bit, on seeded random arms and states: square, redundant (with the null-space
posture torque), a contact point, planar and spatial, a singular Jacobian; the pose increment, the followers' PI
(clipped integral) and the tracking acceleration (angles wrapped); the pose error, the posture torque and the node
torque of :func:`coopctrl.controllers.node_computed_torque` (coopctrl.controllers._kernels), with and without a
posture torque."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.controllers import laws
from coopctrl.controllers import _kernels
from coopctrl.controllers._kernels import control_work, pose_work


def _spd(rng, n, scale):
    A = rng.normal(size=(n, n))
    return A @ A.T * scale + np.eye(n) * scale


@pytest.mark.parametrize("p, n, contact", [(6, 6, False), (6, 7, False), (3, 3, False), (3, 5, False), (6, 6, True),
                                           (3, 3, True)])
def test_arm_torque_matches_the_numba_law_bit_for_bit(p, n, contact):
    rng = np.random.default_rng(1000 * p + n + contact)
    nmax = max(n, p)
    for trial in range(25):
        W = _spd(rng, p, 2.0)
        H = np.zeros((nmax, nmax))
        H[:n, :n] = _spd(rng, n, 0.5)
        J = np.zeros((p, nmax))
        J[:, :n] = rng.normal(size=(p, n))
        if trial == 0 and not contact:
            J[1, :n] = J[0, :n]  # a singular Jacobian
        w_free, S, Jdq, a_cmd = (rng.normal(size=p) for _ in range(4))
        h = rng.normal(size=nmax)
        q, dq, q_rest = (rng.normal(size=nmax) for _ in range(3))
        gain = np.array([25.0, 10.0])
        want, got = np.zeros(nmax), np.zeros(nmax)
        wv, wm = control_work(nmax)
        ok_want = laws.arm_torque_into(contact, n, W, w_free, S, H, h, J, Jdq, a_cmd, q, dq, q_rest, gain, wv, wm,
                                       np.zeros(nmax, np.int64), np.zeros(nmax), want)
        ok_got = _core.arm_torque(contact, n, W, w_free, S, H, h, J, Jdq, a_cmd, q, dq, q_rest, gain, got)
        assert ok_got == ok_want
        np.testing.assert_array_equal(got, want)
        if trial == 0 and not contact and n == p:
            assert not ok_got  # the singular case was met


@pytest.mark.parametrize("spatial", [True, False])
def test_pose_increment_matches_the_numba_law_bit_for_bit(spatial):
    rng = np.random.default_rng(5 + spatial)
    p = 6 if spatial else 3
    for trial in range(50):
        C = _spd(rng, p, 1e-4)
        F, Y0, Yi = rng.normal(size=p), rng.uniform(-1, 1, p), rng.uniform(-1, 1, p)
        if spatial and trial == 0:
            Yi[4] = np.pi / 2  # L(A_i) singular
        want, got = np.zeros(p), np.zeros(p)
        R, v = pose_work()
        ok_want = laws.pose_increment_into(spatial, C, F, Y0, Yi, R, v, want)
        assert _core.pose_increment(spatial, C, F, Y0, Yi, got) == ok_want
        np.testing.assert_array_equal(got, want)


def test_follower_correction_and_tracking_match_the_numba_laws_bit_for_bit():
    rng = np.random.default_rng(3)
    for trial in range(50):
        F_cmd, F_seen = rng.normal(size=6) * 50, rng.normal(size=6) * 50
        integral = rng.normal(size=6)
        mine = integral.copy()
        corr_want, corr_got = np.zeros(6), np.zeros(6)
        loop = trial % 3 != 0
        laws.follower_correction_into(F_cmd, F_seen, integral, 1e-3, 0.5, 20.0, 1.5, loop, corr_want)
        _core.follower_correction(F_cmd, F_seen, mine, 1e-3, 0.5, 20.0, 1.5, loop, corr_got)
        np.testing.assert_array_equal(mine, integral)
        np.testing.assert_array_equal(corr_got, corr_want)
        target, Y = rng.uniform(-7, 7, 6), rng.uniform(-7, 7, 6)  # angles beyond pi: wrapped
        dY_ref, dY, ddY = (rng.normal(size=6) for _ in range(3))
        e1, a1, e2, a2 = (np.zeros(6) for _ in range(4))
        laws.tracking_acceleration_into(target, Y, dY_ref, dY, ddY, 400.0, 40.0, 3, e1, a1)
        _core.tracking_acceleration(target, Y, dY_ref, dY, ddY, 400.0, 40.0, 3, e2, a2)
        np.testing.assert_array_equal(e2, e1)
        np.testing.assert_array_equal(a2, a1)


@pytest.mark.parametrize("p, n, contact", [(6, 6, False), (6, 7, False), (3, 3, False), (3, 5, False), (6, 6, True)])
def test_node_torque_matches_the_numba_kernels_bit_for_bit(p, n, contact):
    rng = np.random.default_rng(77 + 10 * p + n + contact)
    for trial in range(25):
        W = _spd(rng, p, 2.0)
        H = _spd(rng, n, 0.5)
        J = rng.normal(size=(p, n))
        if trial == 0 and not contact:
            J[1] = J[0]  # a singular Jacobian
        w_free, S, Jdq, a_cmd = (rng.normal(size=p) for _ in range(4))
        h = rng.normal(size=n)
        got = np.zeros(n)
        if not contact and n > p:
            tau_0 = rng.normal(size=n) if trial % 2 else None
            want, ok_want = _kernels.node_torque_redundant(W, w_free, S, H, h, J, Jdq, a_cmd,
                                                           np.zeros(n) if tau_0 is None else tau_0)
            ok_got = _core.node_torque(contact, W, w_free, S, H, h, J, Jdq, a_cmd, tau_0, got)
        else:
            want, ok_want = _kernels.node_torque(W, w_free, S, H, h, J, Jdq, a_cmd, contact)
            ok_got = _core.node_torque(contact, W, w_free, S, H, h, J, Jdq, a_cmd, None, got)
        assert ok_got == ok_want
        np.testing.assert_array_equal(got, want)
        if trial == 0 and not contact:
            assert not ok_got  # the singular case was met


def test_pose_error_and_posture_torque_match_the_numba_laws_bit_for_bit():
    rng = np.random.default_rng(11)
    for trial in range(50):
        p, npos = (6, 3) if trial % 2 else (3, 2)
        target, Y = rng.uniform(-9, 9, p), rng.uniform(-9, 9, p)  # angles beyond pi: wrapped
        want, got = np.zeros(p), np.zeros(p)
        laws.pose_error_into(target, Y, npos, want)
        _core.pose_error(target, Y, npos, got)
        np.testing.assert_array_equal(got, want)
        n = 7
        H = _spd(rng, n + 1, 0.3)  # the arm's block is the leading n x n
        q, dq, q_rest = (rng.normal(size=n) for _ in range(3))
        want, got = np.zeros(n), np.zeros(n)
        laws.posture_torque_into(H, q, dq, q_rest, n, 16.0, 8.0, want)
        _core.posture_torque(H, q, dq, q_rest, n, 16.0, 8.0, got)
        np.testing.assert_array_equal(got, want)
