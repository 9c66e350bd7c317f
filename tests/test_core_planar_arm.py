"""plants/core/planar_arm (the compiled core's planar arm, plants._core) on random link tables: ``H`` symmetric
positive definite, the gravity torque at rest the gradient of the potential (central differences), and the
arguments checked once at the binding. The arm's dynamics against Pinocchio, finite differences and energy are
tests/test_arms_planar.py's (``PlanarArm`` calls this core). The bit-for-bit comparison with the numba kernel it
replaced went with it: it was run when the core was ported, and the golden records (tests/golden) lock a run's
numbers."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core


def _random_arm(rng, n):
    links = np.column_stack([rng.uniform(0.2, 1.0, n), rng.uniform(0.5, 5.0, n), rng.uniform(-0.2, 0.6, n),
                             rng.uniform(-0.1, 0.1, n), rng.uniform(0.01, 0.3, n), rng.uniform(0.0, 0.1, n),
                             rng.uniform(0.0, 0.5, n)])
    return (np.ascontiguousarray(links), rng.uniform(-1, 1, 3), rng.uniform(-0.2, 0.2, 3),
            np.array([0.0, -9.81]))


#: Central differences of the potential, step 1e-6 rad on O(1-10) J: truncation ~h^2, rounding ~eps |U| / h.
FD_STEP, FD_TOL = 1e-6, 1e-7


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_planar_arm_terms_are_a_mass_matrix_and_the_potentials_gradient(n):
    rng = np.random.default_rng(100 + n)
    for _ in range(20):
        links, base, tool, gravity = _random_arm(rng, n)
        q = rng.uniform(-np.pi, np.pi, n)
        H, h, Y, J, Jdq = np.zeros((n, n)), np.zeros(n), np.zeros(3), np.zeros((3, n)), np.zeros(3)
        assert _core.planar_arm_terms(q, np.zeros(n), links, base, tool, gravity, H, h, Y, J, Jdq) == 0
        np.testing.assert_array_equal(H, H.T)
        assert np.linalg.eigvalsh(H).min() > 0.0
        grad = np.array([(_core.planar_arm_potential(q + FD_STEP * e, links, base, gravity)
                          - _core.planar_arm_potential(q - FD_STEP * e, links, base, gravity)) / (2 * FD_STEP)
                         for e in np.eye(n)])
        np.testing.assert_allclose(h, grad, rtol=0.0, atol=FD_TOL * (1.0 + np.abs(grad).max()))


def test_planar_arm_terms_refuse_a_wrong_shape_naming_the_argument():
    links, base, tool, gravity = _random_arm(np.random.default_rng(1), 3)
    out = [np.zeros((3, 3)), np.zeros(3), np.zeros(3), np.zeros((3, 3)), np.zeros(3)]
    with pytest.raises(ValueError, match="^q: expected length 3, got 2"):
        _core.planar_arm_terms(np.zeros(2), np.zeros(3), links, base, tool, gravity, *out)
    with pytest.raises(ValueError, match="^links: expected 7 columns"):
        _core.planar_arm_terms(np.zeros(3), np.zeros(3), links[:, :6].copy(), base, tool, gravity, *out)
    out[3] = np.zeros((2, 3))
    with pytest.raises(ValueError, match=r"^J: expected shape \(3, n\) or"):
        _core.planar_arm_terms(np.zeros(3), np.zeros(3), links, base, tool, gravity, *out)
