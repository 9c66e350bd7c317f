"""ZYX Euler angles and the body-rate map (docs/model.md s.2): against scipy's Rotation and
finite differences, and the singularity at theta = +-pi/2."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from plants.errors import EulerSingularityError
from plants.frames import (
    EULER_SINGULARITY_COS,
    body_rate_map,
    body_rate_map_dot,
    body_rate_map_inv,
    euler_zyx_from_rotation,
    rotation_planar,
    rotation_vector,
    rotation_zyx,
    rotation_zyx_partials,
)

SEEDS = list(range(10))
# Closed-form trigonometry against scipy (quaternion based): both exact, so differences are a
# few ulps of O(1) entries; 1e-12 leaves a thousandfold margin.
EXACT_TOL = 1e-12
# Central differences, step 1e-6 on O(1) functions: truncation ~h^2 = 1e-12, rounding
# ~eps/h = 2e-10; 1e-7 absolute is a safe bound that still catches any wrong term (O(1)).
FD_STEP = 1e-6
FD_TOL = 1e-7


def skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def random_angles(rng):
    """psi, phi anywhere; theta well inside (-pi/2, pi/2)."""
    return np.array([rng.uniform(-np.pi, np.pi), rng.uniform(-1.4, 1.4), rng.uniform(-np.pi, np.pi)])


@pytest.mark.parametrize("seed", SEEDS)
def test_rotation_is_orthonormal_and_matches_scipy(seed):
    A = random_angles(np.random.default_rng(seed))
    R = rotation_zyx(A)
    assert np.allclose(R.T @ R, np.eye(3), atol=EXACT_TOL)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=EXACT_TOL)
    # intrinsic "ZYX" = Rz(psi) Ry(theta) Rx(phi): an independent reference
    R_ref = Rotation.from_euler("ZYX", A).as_matrix()
    np.testing.assert_allclose(R, R_ref, atol=EXACT_TOL)


@pytest.mark.parametrize("seed", SEEDS)
def test_rotation_partials_match_finite_differences(seed):
    A = random_angles(np.random.default_rng(seed))
    parts = rotation_zyx_partials(A)
    for k in range(3):
        e = np.zeros(3)
        e[k] = FD_STEP
        fd = (rotation_zyx(A + e) - rotation_zyx(A - e)) / (2 * FD_STEP)
        np.testing.assert_allclose(parts[k], fd, atol=FD_TOL)


@pytest.mark.parametrize("seed", SEEDS)
def test_euler_round_trip(seed):
    rng = np.random.default_rng(seed)
    A = random_angles(rng)
    np.testing.assert_allclose(euler_zyx_from_rotation(rotation_zyx(A)), A, atol=EXACT_TOL)
    # and from an arbitrary rotation matrix (scipy): R(A(R)) = R
    R = Rotation.random(random_state=seed).as_matrix()
    np.testing.assert_allclose(rotation_zyx(euler_zyx_from_rotation(R)), R, atol=EXACT_TOL)


@pytest.mark.parametrize("seed", SEEDS)
def test_body_rate_map_gives_body_angular_velocity(seed):
    rng = np.random.default_rng(seed)
    A, dA = random_angles(rng), rng.normal(size=3)
    R = rotation_zyx(A)
    dR = (rotation_zyx(A + FD_STEP * dA) - rotation_zyx(A - FD_STEP * dA)) / (2 * FD_STEP)
    Omega = R.T @ dR  # = S(omega_body)
    w = body_rate_map(A) @ dA
    np.testing.assert_allclose(Omega, skew(w), atol=FD_TOL * (1 + np.abs(dA).max()))


@pytest.mark.parametrize("seed", SEEDS)
def test_body_rate_map_dot_matches_finite_differences(seed):
    rng = np.random.default_rng(seed)
    A, dA = random_angles(rng), rng.normal(size=3)
    fd = (body_rate_map(A + FD_STEP * dA) - body_rate_map(A - FD_STEP * dA)) / (2 * FD_STEP)
    np.testing.assert_allclose(body_rate_map_dot(A, dA), fd, atol=FD_TOL * (1 + np.abs(dA).max()))


@pytest.mark.parametrize("seed", SEEDS)
def test_body_rate_map_inverse(seed):
    A = random_angles(np.random.default_rng(seed))
    Linv = body_rate_map_inv(A)
    # |theta| <= 1.4: cond(L) <= ~1/cos(1.4) ~ 6, so 1e-12 is still many ulps of margin
    np.testing.assert_allclose(Linv @ body_rate_map(A), np.eye(3), atol=EXACT_TOL)
    np.testing.assert_allclose(body_rate_map(A) @ Linv, np.eye(3), atol=EXACT_TOL)


@pytest.mark.parametrize("theta", [np.pi / 2, -np.pi / 2, np.pi / 2 + 1e-8, np.pi / 2 - 0.5 * EULER_SINGULARITY_COS])
def test_singularity_is_detected(theta):
    A = np.array([0.3, theta, -0.7])
    with pytest.raises(EulerSingularityError) as err:
        body_rate_map_inv(A, "node 3")
    assert "node 3" in str(err.value)
    assert err.value.theta == pytest.approx(theta)


def test_just_outside_the_singular_band_is_regular():
    A = np.array([0.0, np.pi / 2 - 10 * EULER_SINGULARITY_COS, 0.0])
    Linv = body_rate_map_inv(A)
    np.testing.assert_allclose(Linv @ body_rate_map(A), np.eye(3), atol=1e-8)


def test_planar_rotation():
    th = 0.7
    R = rotation_planar(th)
    np.testing.assert_allclose(R.T @ R, np.eye(2), atol=EXACT_TOL)
    # theta measured from +x towards +z: the x axis goes to (cos, sin)
    np.testing.assert_allclose(R @ [1.0, 0.0], [np.cos(th), np.sin(th)], atol=EXACT_TOL)
    # the x-z plane rotation is the spatial rotation about -y (right-handed x, y, z)
    R3 = Rotation.from_euler("y", -th).as_matrix()
    np.testing.assert_allclose(R3[np.ix_([0, 2], [0, 2])], R, atol=EXACT_TOL)


def test_rotation_vector_matches_scipy_at_every_angle():
    """Angles from 0 (the series branch) to pi (where the quaternion's scalar part vanishes), as the arms'
    inverse kinematics take it: scipy's ``Rotation.from_matrix(M).as_rotvec()`` is the reference."""
    rng = np.random.default_rng(7)
    for angle in [0.0, 1e-9, 1e-4, 0.5, 2.0, 3.0, np.pi - 1e-9, np.pi]:
        for _ in range(20):
            axis = rng.normal(size=3)
            rv = angle * axis / np.linalg.norm(axis)
            M = Rotation.from_rotvec(rv).as_matrix()
            out = rotation_vector(M)
            expected = Rotation.from_matrix(M).as_rotvec()
            if angle >= np.pi - 1e-9:  # +-axis * pi are the same rotation: compare the rotations
                assert np.linalg.norm(out) == pytest.approx(np.linalg.norm(expected), abs=1e-7)
                assert np.allclose(Rotation.from_rotvec(out).as_matrix(), M, atol=1e-12)
            else:  # a few ulps of the matrix entries (EXACT_TOL)
                assert np.allclose(out, expected, rtol=0.0, atol=EXACT_TOL), (angle, out, expected)
