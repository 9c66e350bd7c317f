"""plants/core/frames (the compiled core's ZYX Euler angles, R(A), L(A), dL/dt, L^-1, the rotation vector and the
planar rotation, plants._core): the same numbers as the numba kernels (plants/frames.py, plants/_frames_kernels.py),
bit for bit (the same expressions in
the same order, without contraction into fused multiply-adds; the sines, cosines and arc tangents from the same C
library), and the arguments checked once at the binding. The oracles of the maths itself (scipy's Rotation, finite
differences) are tests/test_frames.py's, on the kernels these equal."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core, _frames_kernels
from plants import frames

SEEDS = range(5)
DRAWS = 40


def _angles(rng):
    """psi, phi anywhere, theta in (-pi/2, pi/2) and some draws beyond it (the formulas hold everywhere)."""
    return rng.uniform([-np.pi, -2.0, -np.pi], [np.pi, 2.0, np.pi])


@pytest.mark.parametrize("seed", SEEDS)
def test_rotation_and_partials_match_the_numba_kernels_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    for _ in range(DRAWS):
        A = _angles(rng)
        R = np.empty((3, 3))
        _core.rotation_zyx_into(A, R)
        np.testing.assert_array_equal(R, _frames_kernels.rotation_zyx(A))
        parts = [np.empty((3, 3)) for _ in range(3)]
        _core.rotation_zyx_partials_into(A, *parts)
        for got, want in zip(parts, _frames_kernels.rotation_zyx_partials(A)):
            np.testing.assert_array_equal(got, want)
        R2, dR = np.empty((3, 3)), np.empty((3, 3, 3))
        R_ref, dR_ref = np.empty((3, 3)), np.empty((3, 3, 3))
        _core.rotation_zyx_and_partials_into(A, R2, dR)
        frames.rotation_zyx_and_partials_into(A, R_ref, dR_ref)
        np.testing.assert_array_equal(R2, R_ref)
        np.testing.assert_array_equal(dR, dR_ref)


@pytest.mark.parametrize("seed", SEEDS)
def test_euler_angles_and_body_rate_maps_match_the_numba_kernels_bit_for_bit(seed):
    rng = np.random.default_rng(10 + seed)
    for _ in range(DRAWS):
        A, dA = _angles(rng), rng.uniform(-3.0, 3.0, 3)
        R = _frames_kernels.rotation_zyx(A)
        got = np.empty(3)
        _core.euler_zyx_from_rotation_into(R, got)
        np.testing.assert_array_equal(got, _frames_kernels.euler_zyx_from_rotation(R))
        L, Ld, Linv, Linv_ref = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3))
        _core.body_rate_map_into(A, L)
        np.testing.assert_array_equal(L, _frames_kernels.body_rate_map(A))
        _core.body_rate_map_dot_into(A, dA, Ld)
        np.testing.assert_array_equal(Ld, _frames_kernels.body_rate_map_dot(A, dA))
        assert _core.body_rate_map_inverse_into(A, Linv) == frames.body_rate_map_inverse(A, Linv_ref) is True
        np.testing.assert_array_equal(Linv, Linv_ref)
        R2, R2_ref = np.empty((2, 2)), _frames_kernels.rotation_planar(A[0])
        _core.rotation_planar_into(float(A[0]), R2)
        np.testing.assert_array_equal(R2, R2_ref)


def test_body_rate_map_inverse_refuses_the_singular_band_and_leaves_its_output():
    Linv = np.full((3, 3), 7.0)
    for theta in (np.pi / 2, -np.pi / 2, np.pi / 2 + 0.5e-6):
        assert not _core.body_rate_map_inverse_into(np.array([0.3, theta, -0.2]), Linv)
        assert not frames.body_rate_map_inverse(np.array([0.3, theta, -0.2]), np.empty((3, 3)))
    np.testing.assert_array_equal(Linv, 7.0)
    assert _core.EULER_SINGULARITY_COS == frames.EULER_SINGULARITY_COS


def _rotation_about(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * K @ K


@pytest.mark.parametrize("seed", SEEDS)
def test_rotation_vector_matches_the_python_function_bit_for_bit_in_every_branch(seed):
    """Random rotations (small: the series branch; near pi about each axis: Shepperd's three other branches)."""
    rng = np.random.default_rng(20 + seed)
    cases = [frames.rotation_zyx(_angles(rng)) for _ in range(DRAWS)]
    cases += [_rotation_about(rng.normal(size=3), rng.uniform(0.0, 1e-3)) for _ in range(10)]
    for axis in np.eye(3):
        cases += [_rotation_about(axis + 0.1 * rng.normal(size=3), np.pi - rng.uniform(0.0, 0.2)) for _ in range(5)]
    branches = set()
    for M in cases:
        M = np.ascontiguousarray(M)
        got, want = np.empty(3), np.empty(3)
        _core.rotation_vector_into(M, got)
        frames.rotation_vector_into(M, want)
        np.testing.assert_array_equal(got, want)
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
def test_the_public_functions_return_the_numba_kernels_numbers_from_any_array_like(seed):
    """plants.frames' functions that return new arrays call the core: the kernels' numbers, from contiguous
    arrays, strided views and lists alike."""
    rng = np.random.default_rng(30 + seed)
    for _ in range(DRAWS):
        A, dA = rng.uniform(-1.5, 1.5, (3, 4))[:, 1], rng.uniform(-3.0, 3.0, 3)  # A: a strided view
        Ac = np.ascontiguousarray(A)
        np.testing.assert_array_equal(frames.rotation_zyx(A), _frames_kernels.rotation_zyx(Ac))
        np.testing.assert_array_equal(frames.rotation_zyx(list(Ac)), _frames_kernels.rotation_zyx(Ac))
        for got, want in zip(frames.rotation_zyx_partials(A), _frames_kernels.rotation_zyx_partials(Ac)):
            np.testing.assert_array_equal(got, want)
        R = _frames_kernels.rotation_zyx(Ac)
        np.testing.assert_array_equal(frames.euler_zyx_from_rotation(R.T.T), _frames_kernels.euler_zyx_from_rotation(R))
        np.testing.assert_array_equal(frames.body_rate_map(A), _frames_kernels.body_rate_map(Ac))
        np.testing.assert_array_equal(frames.body_rate_map_dot(A, dA), _frames_kernels.body_rate_map_dot(Ac, dA))
        np.testing.assert_array_equal(frames.rotation_planar(A[0]), _frames_kernels.rotation_planar(A[0]))
        Linv = np.empty((3, 3))
        assert frames.body_rate_map_inverse(Ac, Linv)
        np.testing.assert_array_equal(frames.body_rate_map_inv(A), Linv)
