"""Tests of coopctrl.trajectory.quaternion against scipy.spatial.transform and plants.frames."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from coopctrl.trajectory import quaternion as quat
from plants.frames import euler_zyx_from_rotation, rotation_zyx


def scipy_q(q):
    """scipy's scalar-last order."""
    return np.asarray(q)[..., [1, 2, 3, 0]]


def test_zyx_conversions_match_scipy_and_the_plant():
    rng = np.random.default_rng(1)
    A = rng.uniform(-3.0, 3.0, (50, 3))
    q = quat.from_zyx(A)
    R = Rotation.from_euler("ZYX", A)  # intrinsic z-y'-x'': Rz(psi) Ry(theta) Rx(phi)
    # same rotation (matrices agree to rounding of a few products: 1e-14)
    np.testing.assert_allclose(quat.matrix(q), R.as_matrix(), atol=1e-14)
    np.testing.assert_allclose(quat.matrix(q), np.array([rotation_zyx(a) for a in A]), atol=1e-14)
    principal, cos_theta = quat.to_zyx(q)
    np.testing.assert_allclose(principal, np.array([euler_zyx_from_rotation(m) for m in quat.matrix(q)]), atol=1e-13)
    np.testing.assert_allclose(cos_theta, np.abs(np.cos(A[:, 1])), atol=1e-14)


def test_exp_log_match_scipy_rotvec_at_small_and_near_half_turn_angles():
    rng = np.random.default_rng(2)
    axes = rng.normal(size=(6, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = np.array([0.0, 1e-12, 1e-6, 1.0, np.pi - 1e-9, np.pi - 1e-3])
    phi = axes * angles[:, None]
    q = quat.exp(phi)
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-15)
    np.testing.assert_allclose(quat.matrix(q), Rotation.from_rotvec(phi).as_matrix(), atol=1e-14)
    # log inverts exp to rounding at every angle (atan2: no loss near 0 or pi)
    np.testing.assert_allclose(quat.log(q), phi, rtol=1e-13, atol=1e-16)
    np.testing.assert_allclose(quat.log(quat.shortest(-q)), phi, rtol=1e-13, atol=1e-16)


def test_multiply_rotate_and_conjugate_match_scipy():
    rng = np.random.default_rng(3)
    a, b = Rotation.random(10, random_state=4), Rotation.random(10, random_state=5)
    qa, qb = a.as_quat()[:, [3, 0, 1, 2]], b.as_quat()[:, [3, 0, 1, 2]]
    np.testing.assert_allclose(quat.matrix(quat.multiply(qa, qb)), (a * b).as_matrix(), atol=1e-14)
    np.testing.assert_allclose(quat.matrix(quat.conjugate(qa)), a.inv().as_matrix(), atol=1e-14)
    v = rng.normal(size=(10, 3))
    np.testing.assert_allclose(quat.rotate(qa, v), a.apply(v), atol=1e-14)


def test_shortest_takes_the_short_way_and_a_half_turn_by_its_axis():
    q = quat.exp(np.array([0.0, 0.0, 2.5]))
    np.testing.assert_array_equal(quat.shortest(-q), q)
    # a half turn about z written with either sign (as rounding of psi = +-pi gives) -> axis +z
    for w in (1e-17, -1e-17, 0.0):
        np.testing.assert_allclose(quat.log(quat.shortest([w, 0.0, 0.0, -1.0])), [0.0, 0.0, np.pi], atol=1e-15)


def test_nearest_zyx_is_the_same_rotation_and_closest_of_its_representatives():
    rng = np.random.default_rng(6)
    A = rng.uniform(-1.4, 1.4, (40, 3))
    principal = quat.to_zyx(quat.from_zyx(A))[0]
    cands = [principal, principal + [np.pi, 0, np.pi]]
    cands[1][:, 1] = np.pi - principal[:, 1]
    ref = rng.uniform(-9.0, 9.0, (40, 3))
    out = quat.nearest_zyx(principal, ref)
    np.testing.assert_allclose(quat.matrix(quat.from_zyx(out)), quat.matrix(quat.from_zyx(A)), atol=1e-13)
    # brute force over both families and whole turns -2..2 in each angle
    turns = np.stack(np.meshgrid(*[np.arange(-2, 3)] * 3, indexing="ij"), -1).reshape(-1, 3) * 2 * np.pi
    for k in range(40):
        best = min((np.sum((c[k] + t - ref[k]) ** 2) for c in cands for t in turns))
        assert np.sum((out[k] - ref[k]) ** 2) == pytest.approx(best, rel=1e-12)
