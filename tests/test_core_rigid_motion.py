"""plants/core/rigid_motion (plants._core.nominal_node_motion, behind plants.cooperative.nominal_node_motion): the
same numbers as the numba kernels the loop's tick runs (spatial_motion_into, planar_motion_into), bit for bit, on
seeded object motions and grasps, the Euler-singular node included; and the rigid-body kinematics against finite
differences of the poses along a motion."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core
from plants.cooperative.loaded_state import motion_work, nominal_node_motion, planar_motion_into, spatial_motion_into


@pytest.mark.parametrize("m", [1, 2, 3])
def test_spatial_and_planar_motion_match_the_numba_kernels_bit_for_bit(m):
    rng = np.random.default_rng(40 + m)
    for trial in range(30):
        Y0, dY0, ddY0 = rng.uniform(-1, 1, 6), rng.normal(size=6), rng.normal(size=6)
        G = np.column_stack([rng.uniform(-0.3, 0.3, (m, 3)), rng.uniform(-1, 1, (m, 3))])
        if trial == 0:
            G[0, 3:] = 0.0
            Y0[3:] = (0.2, np.pi / 2, -0.1)  # the first node's frame at the singularity
        want = [np.empty((m + 1, 6)) for _ in range(3)]
        got = [np.empty((m + 1, 6)) for _ in range(3)]
        bad = spatial_motion_into(Y0, dY0, ddY0, G, *want, *motion_work())
        assert _core.nominal_node_motion(Y0, dY0, ddY0, G, *got) == bad
        for a, b in zip(got, want):
            np.testing.assert_array_equal(a, b)
        Gp = np.ascontiguousarray(G[:, :3])
        want = [np.empty((m + 1, 3)) for _ in range(3)]
        got = [np.empty((m + 1, 3)) for _ in range(3)]
        planar_motion_into(Y0[:3], dY0[:3], ddY0[:3], Gp, *want)
        assert _core.nominal_node_motion(Y0[:3], dY0[:3], ddY0[:3], Gp, *got) == -1
        for a, b in zip(got, want):
            np.testing.assert_array_equal(a, b)


def test_the_node_rates_are_the_derivatives_of_the_node_poses():
    """Central differences of Y_j(t) along a smooth object motion Y0(t) give dY_j (and of dY_j give ddY_j) to the
    differences' truncation, O(h^2) = 1e-8 relative at h = 1e-4 s."""
    rng = np.random.default_rng(2)
    G = np.column_stack([rng.uniform(-0.3, 0.3, (2, 3)), rng.uniform(-0.5, 0.5, (2, 3))])
    c0, c1, c2 = rng.uniform(-0.5, 0.5, 6), rng.normal(size=6), rng.normal(size=6)

    def motion(t):
        return c0 + c1 * t + c2 * t * t, c1 + 2 * c2 * t, 2 * c2

    h, t = 1e-4, 0.3
    Y, dY, ddY = nominal_node_motion(*motion(t), G)
    Yp, dYp, _ = nominal_node_motion(*motion(t + h), G)
    Ym, dYm, _ = nominal_node_motion(*motion(t - h), G)
    np.testing.assert_allclose((Yp - Ym) / (2 * h), dY, atol=1e-6)
    np.testing.assert_allclose((dYp - dYm) / (2 * h), ddY, atol=1e-6)
