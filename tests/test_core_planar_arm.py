"""plants/core/planar_arm (the compiled core's planar arm, plants._core): the same numbers as the numba kernel it
replaces, bit for bit (both evaluate the same expressions in the same order, without contraction into fused
multiply-adds), and its arguments checked once at the binding."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core
from plants.arms import _planar_kernels as numba_kernels


def _random_arm(rng, n):
    links = np.column_stack([rng.uniform(0.2, 1.0, n), rng.uniform(0.5, 5.0, n), rng.uniform(-0.2, 0.6, n),
                             rng.uniform(-0.1, 0.1, n), rng.uniform(0.01, 0.3, n), rng.uniform(0.0, 0.1, n),
                             rng.uniform(0.0, 0.5, n)])
    return (np.ascontiguousarray(links), rng.uniform(-1, 1, 3), rng.uniform(-0.2, 0.2, 3),
            np.array([0.0, -9.81]))


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_planar_arm_terms_match_the_numba_kernel_bit_for_bit(n):
    rng = np.random.default_rng(100 + n)
    for _ in range(20):
        links, base, tool, gravity = _random_arm(rng, n)
        q, dq = rng.uniform(-np.pi, np.pi, n), rng.uniform(-3, 3, n)
        core = [np.zeros((n, n)), np.zeros(n), np.zeros(3), np.zeros((3, n)), np.zeros(3)]
        ref = [np.zeros((n, n)), np.zeros(n), np.zeros(3), np.zeros((3, n)), np.zeros(3)]
        assert _core.planar_arm_terms(q, dq, links, base, tool, gravity, *core) == 0
        numba_kernels.planar_arm_terms(q, dq, links, base, tool, gravity, *ref)
        for got, want in zip(core, ref):
            np.testing.assert_array_equal(got, want)
        assert _core.planar_arm_potential(q, links, base, gravity) == numba_kernels.planar_arm_potential(
            q, links, base, gravity)


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
