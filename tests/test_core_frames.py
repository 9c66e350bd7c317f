"""plants/core/frames (the compiled core's ZYX Euler angles, R(A), L(A), dL/dt, L^-1, the rotation vector and the
planar rotation, plants._core): the fused entry points give the bits of the separate ones, the singular band is
refused without touching the output, every branch of the rotation vector agrees with scipy, the arguments are
checked once at the binding, and plants.frames' functions give the core's numbers from any array-like.

The maths itself is held to scipy's Rotation and finite differences in tests/test_frames.py. The bit-for-bit
comparison with the numba kernels these replaced went with them: it was run when the core was ported, and the
golden records (tests/golden) lock a run's numbers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from plants import _core
from plants import frames

SEEDS = range(5)
DRAWS = 40
#: The rotation vector against scipy's (both exact): a few ulps of O(1) entries (tests/test_frames.py's bound).
EXACT_TOL = 1e-12


def _angles(rng):
    """psi, phi anywhere, theta in (-pi/2, pi/2) and some draws beyond it (the formulas hold everywhere)."""
    return rng.uniform([-np.pi, -2.0, -np.pi], [np.pi, 2.0, np.pi])


@pytest.mark.parametrize("seed", SEEDS)
def test_rotation_and_partials_in_one_call_are_the_separate_calls_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    for _ in range(DRAWS):
        A = _angles(rng)
        R = np.empty((3, 3))
        _core.rotation_zyx_into(A, R)
        parts = [np.empty((3, 3)) for _ in range(3)]
        _core.rotation_zyx_partials_into(A, *parts)
        R2, dR = np.full((3, 3), np.nan), np.full((3, 3, 3), np.nan)
        _core.rotation_zyx_and_partials_into(A, R2, dR)
        np.testing.assert_array_equal(R2, R)
        np.testing.assert_array_equal(dR, np.stack(parts))


def test_body_rate_map_inverse_refuses_the_singular_band_and_leaves_its_output():
    Linv = np.full((3, 3), 7.0)
    for theta in (np.pi / 2, -np.pi / 2, np.pi / 2 + 0.5e-6):
        assert not _core.body_rate_map_inverse_into(np.array([0.3, theta, -0.2]), Linv)
    np.testing.assert_array_equal(Linv, 7.0)
    assert _core.body_rate_map_inverse_into(np.array([0.3, np.pi / 2 - 2e-6, -0.2]), Linv)  # just outside it
    assert _core.EULER_SINGULARITY_COS == frames.EULER_SINGULARITY_COS


def _rotation_about(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


@pytest.mark.parametrize("seed", SEEDS)
def test_rotation_vector_matches_scipy_in_every_branch(seed):
    """Random rotations (small: the series branch; near pi about each axis: Shepperd's three other branches),
    against scipy's ``as_rotvec`` (angles up to pi - 0.0, where the axis is still defined by its sign)."""
    rng = np.random.default_rng(20 + seed)
    cases = [frames.rotation_zyx(_angles(rng)) for _ in range(DRAWS)]
    cases += [_rotation_about(rng.normal(size=3), rng.uniform(0.0, 1e-3)) for _ in range(10)]
    for axis in np.eye(3):
        cases += [_rotation_about(axis + 0.1 * rng.normal(size=3), np.pi - rng.uniform(1e-3, 0.2)) for _ in range(5)]
    branches = set()
    for M in cases:
        M = np.ascontiguousarray(M)
        got = np.empty(3)
        _core.rotation_vector_into(M, got)
        np.testing.assert_allclose(got, Rotation.from_matrix(M).as_rotvec(), rtol=0.0, atol=EXACT_TOL)
        d = np.diag(M)
        branches.add(-1 if np.trace(M) >= d.max() else int(np.argmax(d)))
    assert branches == {-1, 0, 1, 2}


def test_frames_refuse_a_wrong_shape_naming_the_argument():
    with pytest.raises(ValueError, match="^A: expected length 3, got 2"):
        _core.rotation_zyx_into(np.zeros(2), np.empty((3, 3)))
    with pytest.raises(ValueError, match=r"^R: expected shape \(3, 3\)"):
        _core.rotation_zyx_into(np.zeros(3), np.empty((3, 2)))
    with pytest.raises(ValueError, match=r"^dR: expected shape \(3, 3, 3\)"):
        _core.rotation_zyx_and_partials_into(np.zeros(3), np.empty((3, 3)), np.empty((2, 3, 3)))
    with pytest.raises(ValueError, match=r"^M: expected shape \(3, 3\)"):
        _core.rotation_vector_into(np.eye(4), np.empty(3))


@pytest.mark.parametrize("seed", SEEDS[:2])
def test_the_public_functions_return_the_cores_numbers_from_any_array_like(seed):
    """plants.frames' functions call the core: its numbers on a contiguous copy, from strided views and lists alike."""
    rng = np.random.default_rng(30 + seed)
    for _ in range(DRAWS):
        A, dA = rng.uniform(-1.5, 1.5, (3, 4))[:, 1], rng.uniform(-3.0, 3.0, 3)  # A: a strided view
        Ac = np.ascontiguousarray(A)
        R, L, Ld, Linv, A_back, R2, rv = (np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)),
                                          np.empty(3), np.empty((2, 2)), np.empty(3))
        parts = [np.empty((3, 3)) for _ in range(3)]
        _core.rotation_zyx_into(Ac, R)
        _core.rotation_zyx_partials_into(Ac, *parts)
        _core.euler_zyx_from_rotation_into(R, A_back)
        _core.body_rate_map_into(Ac, L)
        _core.body_rate_map_dot_into(Ac, dA, Ld)
        assert _core.body_rate_map_inverse_into(Ac, Linv)
        _core.rotation_planar_into(float(A[0]), R2)
        _core.rotation_vector_into(R, rv)
        np.testing.assert_array_equal(frames.rotation_zyx(A), R)
        np.testing.assert_array_equal(frames.rotation_zyx(list(Ac)), R)
        for got, want in zip(frames.rotation_zyx_partials(A), parts):
            np.testing.assert_array_equal(got, want)
        np.testing.assert_array_equal(frames.euler_zyx_from_rotation(R.T.T), A_back)
        np.testing.assert_array_equal(frames.euler_zyx_from_rotation(R.T.tolist()), frames.euler_zyx_from_rotation(R.T))
        np.testing.assert_array_equal(frames.body_rate_map(A), L)
        np.testing.assert_array_equal(frames.body_rate_map_dot(A, dA), Ld)
        np.testing.assert_array_equal(frames.body_rate_map_inv(A), Linv)
        np.testing.assert_array_equal(frames.rotation_planar(A[0]), R2)
        np.testing.assert_array_equal(frames.rotation_vector(R.tolist()), rv)
