"""coopctrl/core/control_laws (coopctrl._core): the computed torque and the pose increment against their numpy
statements, on seeded random arms and states: square, redundant (with the null-space posture torque), a contact
point, planar and spatial, a singular Jacobian.

The laws were checked bit for bit against the numba kernels they replaced when they were ported; the golden
records (tests/golden) lock the loop's numbers since. These tests keep what an independent reference can check:
the formulas of :func:`coopctrl.controllers.node_computed_torque` and of
:meth:`GraspCompliance.pose_increment <coopctrl.controllers.GraspCompliance.pose_increment>` written in numpy
(the simple laws, the pose error, the PI, the tracking acceleration and the posture torque, are checked in
tests/test_controllers_laws.py)."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from plants.frames import body_rate_map_inv, rotation_planar, rotation_zyx

#: Agreement of the core with the numpy statement, relative to the result and to the condition number of the
#: matrix solved: both round differently, by about 1e-16 per operation; a wrong term is of order one.
REL = 1e-12


def _spd(rng, n, scale):
    A = rng.normal(size=(n, n))
    return A @ A.T * scale + np.eye(n) * scale


def _node_torque(contact, W, w_free, S, H, h, J, Jdq, a_cmd, tau_0):
    """The computed torque in numpy (node_computed_torque's docstring): ``F = W a + w_free + S``; a contact point
    gives ``F``; a square arm ``H J^-1 (a - Jdq) + h + J^T F``; a redundant arm ``H J^# (a - Jdq) + h + J^T F +
    P^T tau_0`` with ``N = H + J^T W J``, ``J^# = N^-1 J^T (J N^-1 J^T)^-1``, ``P^T = I - J^T J^{#T}``."""
    F = W @ a_cmd + w_free + S
    if contact:
        return F
    p, n = J.shape
    if n == p:
        return H @ np.linalg.solve(J, a_cmd - Jdq) + h + J.T @ F
    Ninv_Jt = np.linalg.solve(H + J.T @ W @ J, J.T)
    J_sharp = Ninv_Jt @ np.linalg.inv(J @ Ninv_Jt)
    tau = H @ (J_sharp @ (a_cmd - Jdq)) + h + J.T @ F
    return tau if tau_0 is None else tau + (np.eye(n) - J.T @ J_sharp.T) @ tau_0


def _scale(J, H, W, want):
    """The tolerance's scale: the result's size times the condition number of what is solved."""
    p, n = J.shape
    cond = np.linalg.cond(J) if n == p else np.linalg.cond(H + J.T @ W @ J) * np.linalg.cond(J @ J.T)
    return cond * max(1.0, np.max(np.abs(want)))


@pytest.mark.parametrize("p, n, contact", [(6, 6, False), (6, 7, False), (3, 3, False), (3, 5, False), (6, 6, True)])
def test_node_torque_is_the_computed_torque(p, n, contact):
    rng = np.random.default_rng(77 + 10 * p + n + contact)
    for trial in range(25):
        W = _spd(rng, p, 2.0)
        H = _spd(rng, n, 0.5)
        J = rng.normal(size=(p, n))
        if trial == 0 and not contact:
            J[1] = J[0]  # a singular Jacobian
        w_free, S, Jdq, a_cmd = (rng.normal(size=p) for _ in range(4))
        h = rng.normal(size=n)
        tau_0 = rng.normal(size=n) if not contact and n > p and trial % 2 else None
        got = np.zeros(n)
        ok = _core.node_torque(contact, W, w_free, S, H, h, J, Jdq, a_cmd, tau_0, got)
        if trial == 0 and not contact:
            assert not ok  # the singular case is refused
            continue
        assert ok
        want = _node_torque(contact, W, w_free, S, H, h, J, Jdq, a_cmd, tau_0)
        got = got[:p] if contact else got
        assert np.max(np.abs(got - want)) <= REL * _scale(J, H, W, want)


@pytest.mark.parametrize("p, n, contact", [(6, 6, False), (6, 7, False), (3, 3, False), (3, 5, False), (6, 6, True),
                                           (3, 3, True)])
def test_arm_torque_adds_the_posture_torque_of_a_redundant_arm(p, n, contact):
    """``arm_torque`` on an arm's blocks in arrays of ``nmax`` columns: the computed torque, plus for a redundant arm
    the null-space image of ``tau_0 = tr(H) / n (Kp (q_rest - q) - Kd dq)``."""
    rng = np.random.default_rng(1000 * p + n + contact)
    nmax = max(n, p) + 1  # the arm's block sits in larger arrays
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
        Kp, Kd = 25.0, 10.0
        got = np.zeros(nmax)
        ok = _core.arm_torque(contact, n, W, w_free, S, H, h, J, Jdq, a_cmd, q, dq, q_rest, np.array([Kp, Kd]), got)
        if trial == 0 and not contact:
            assert not ok
            continue
        assert ok
        Ha, Ja, ha = H[:n, :n], J[:, :n], h[:n]
        tau_0 = None
        if not contact and n > p:
            tau_0 = np.trace(Ha) / n * (Kp * (q_rest[:n] - q[:n]) - Kd * dq[:n])
        want = _node_torque(contact, W, w_free, S, Ha, ha, Ja, Jdq, a_cmd, tau_0)
        got = got[:p] if contact else got[:n]
        assert np.max(np.abs(got - want)) <= REL * _scale(Ja, Ha, W, want)


@pytest.mark.parametrize("spatial", [True, False])
def test_pose_increment_maps_the_wrench_through_the_compliance(spatial):
    """``d = C R0^T F`` (object frame); the position ``R0 d[:npos]``; spatial angles ``L(A_i)^-1 R_i^T R0 d[3:]``,
    planar angle ``d[2]``; a singular ``L(A_i)`` is refused (spatial)."""
    rng = np.random.default_rng(5 + spatial)
    p = 6 if spatial else 3
    for trial in range(50):
        C = _spd(rng, p, 1e-4)
        F, Y0, Yi = rng.normal(size=p), rng.uniform(-1, 1, p), rng.uniform(-1, 1, p)
        if spatial and trial == 0:
            Yi[4] = np.pi / 2  # L(A_i) singular
        got = np.zeros(p)
        ok = _core.pose_increment(spatial, C, F, Y0, Yi, got)
        if spatial and trial == 0:
            assert not ok
            continue
        assert ok
        if spatial:
            R0, Ri = rotation_zyx(Y0[3:6]), rotation_zyx(Yi[3:6])
            Rb = np.zeros((6, 6))
            Rb[:3, :3] = Rb[3:, 3:] = R0
            d = C @ (Rb.T @ F)
            want = np.concatenate([R0 @ d[:3], body_rate_map_inv(Yi[3:6]) @ (Ri.T @ (R0 @ d[3:]))])
        else:
            R0 = rotation_planar(Y0[2])
            d = C @ np.concatenate([R0.T @ F[:2], F[2:]])
            want = np.concatenate([R0 @ d[:2], d[2:]])
        assert np.max(np.abs(got - want)) <= REL * 1e2 * max(np.max(np.abs(want)), 1e-300)
