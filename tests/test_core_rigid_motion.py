"""plants/core/rigid_motion (plants._core.nominal_node_motion, behind plants.cooperative.nominal_node_motion): the
rigid-body kinematics of the nodes carried by the object against the formulas of docs/model.md (148) written
with numpy here, on seeded object motions and grasps, the Euler-singular node included; and against finite
differences of the poses along a motion. The bit-for-bit comparison with the numba kernels these replaced went
with them: it was run when the core was ported, and the golden records (tests/golden) lock a run's numbers."""

from __future__ import annotations

import numpy as np
import pytest

from plants import _core
from plants.cooperative.loaded_state import nominal_node_motion
from plants.frames import body_rate_map, body_rate_map_dot, body_rate_map_inv, euler_zyx_from_rotation, rotation_zyx

#: The core against the numpy statement of the same formulas: the same maths in another order, a few ulps of
#: O(1) quantities (rates amplified by ``L^-1``, at most ~1/cos(theta) ~ 10 for the angles drawn here).
FORMULA_TOL = 1e-11


def _spatial_reference(Y0, dY0, ddY0, G):
    """(148) and its derivatives with numpy: ``r_j = r_0 + R_0 rho``, ``R_j = R_0 R(A_0j)``, ``omega = R_0 L dA_0``,
    ``alpha = R_0 (L ddA_0 + dL dA_0)``, ``dA_j = L_j^-1 R_j^T omega``, ``ddA_j = L_j^-1 (R_j^T alpha - dL_j dA_j)``."""
    R0, A0, dA0 = rotation_zyx(Y0[3:]), Y0[3:], dY0[3:]
    omega = R0 @ body_rate_map(A0) @ dA0
    alpha = R0 @ (body_rate_map(A0) @ ddY0[3:] + body_rate_map_dot(A0, dA0) @ dA0)
    Y, dY, ddY = [Y0], [dY0], [ddY0]
    for g in G:
        d = R0 @ g[:3]
        Aj = euler_zyx_from_rotation(R0 @ rotation_zyx(g[3:]))
        Rj = rotation_zyx(Aj)
        Linv = body_rate_map_inv(Aj)
        dAj = Linv @ Rj.T @ omega
        ddAj = Linv @ (Rj.T @ alpha - body_rate_map_dot(Aj, dAj) @ dAj)
        Y.append(np.concatenate([Y0[:3] + d, Aj]))
        dY.append(np.concatenate([dY0[:3] + np.cross(omega, d), dAj]))
        ddY.append(np.concatenate([ddY0[:3] + np.cross(alpha, d) + np.cross(omega, np.cross(omega, d)), ddAj]))
    return np.array(Y), np.array(dY), np.array(ddY)


def _planar_reference(Y0, dY0, ddY0, G):
    """(148) in the plane: ``d = R(theta) rho``, ``dr_j = dr_0 + w (-d_z, d_x)``, ``ddr_j = ddr_0 + al (-d_z, d_x) - w^2 d``."""
    th, w, al = Y0[2], dY0[2], ddY0[2]
    R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
    Y, dY, ddY = [Y0], [dY0], [ddY0]
    for g in G:
        d = R @ g[:2]
        perp = np.array([-d[1], d[0]])
        Y.append(np.concatenate([Y0[:2] + d, [th + g[2]]]))
        dY.append(np.concatenate([dY0[:2] + w * perp, [w]]))
        ddY.append(np.concatenate([ddY0[:2] + al * perp - w * w * d, [al]]))
    return np.array(Y), np.array(dY), np.array(ddY)


@pytest.mark.parametrize("m", [1, 2, 3])
def test_spatial_and_planar_motion_are_the_rigid_body_formulas(m):
    rng = np.random.default_rng(40 + m)
    for trial in range(30):
        Y0, dY0, ddY0 = rng.uniform(-1, 1, 6), rng.normal(size=6), rng.normal(size=6)
        G = np.column_stack([rng.uniform(-0.3, 0.3, (m, 3)), rng.uniform(-1, 1, (m, 3))])
        got = [np.full((m + 1, 6), np.nan) for _ in range(3)]
        if trial == 0:
            G[0, 3:] = 0.0
            Y0[3:] = (0.2, np.pi / 2, -0.1)  # the first node's frame at the singularity: reported, its rates zero
            assert _core.nominal_node_motion(Y0, dY0, ddY0, G, *got) == 1
            np.testing.assert_array_equal(got[1][1, 3:], 0.0)
            np.testing.assert_array_equal(got[2][1, 3:], 0.0)
            continue
        assert _core.nominal_node_motion(Y0, dY0, ddY0, G, *got) == -1
        for a, b in zip(got, _spatial_reference(Y0, dY0, ddY0, G)):
            np.testing.assert_allclose(a, b, rtol=0.0, atol=FORMULA_TOL * (1.0 + np.abs(b).max()))
        Gp = np.ascontiguousarray(G[:, :3])
        got = [np.full((m + 1, 3), np.nan) for _ in range(3)]
        assert _core.nominal_node_motion(Y0[:3], dY0[:3], ddY0[:3], Gp, *got) == -1
        for a, b in zip(got, _planar_reference(Y0[:3], dY0[:3], ddY0[:3], Gp)):
            np.testing.assert_allclose(a, b, rtol=0.0, atol=FORMULA_TOL * (1.0 + np.abs(b).max()))


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
