"""The QP's rows are written once (issue 10, Layout): ``LoadDistributionProblem.update`` and the public
helpers ``grasp_matrix`` / ``internal_force_basis`` call the C++ core's assembly (``coopctrl._core``,
coopctrl/core/qp_assembly.h), which the compiled tick calls too; the rows are checked here against their
statements (the class docstring, the rows' statements of tests/test_core_qp_assembly.py, the analytic grasp).

Seeded random spatial and planar configurations with the three inequality families (min_grip,
friction, torque_limits) and a desired squeeze."""

from __future__ import annotations

import numpy as np
import pytest
from test_core_qp_assembly import friction_rows

from coopctrl.errors import ScenarioError
from coopctrl.load_distribution import LoadDistributionConfig, LoadDistributionProblem, grasp_matrix, internal_force_basis

K_OF = {"spatial": 6, "planar": 3}
P_OF = {"spatial": 3, "planar": 2}


def random_inputs(space: str, m: int, seed: int):
    """Contacts, object centre, load, normals, per-arm Jacobians (k x n_i), biases and torque limits."""
    rng = np.random.default_rng(seed)
    k, p = K_OF[space], P_OF[space]
    r0 = rng.normal(size=p) * 0.1
    r = r0 + rng.normal(size=(m, p)) * 0.3
    w = rng.normal(size=k) * 20.0
    normals = rng.normal(size=(m, p))  # not unit: update normalises them
    counts = [int(c) for c in rng.integers(2, 8, size=m)]
    J = [rng.normal(size=(k, c)) for c in counts]
    bias = [rng.normal(size=c) * 5.0 for c in counts]
    tau_max = [np.abs(rng.normal(size=c)) * 50.0 + 1.0 for c in counts]
    return r, r0, w, normals, J, bias, tau_max


def config(space: str, m: int) -> LoadDistributionConfig:
    return LoadDistributionConfig(squeeze=tuple(float(s) for s in np.arange(1, m * (m - 1) // 2 + 1)),
                                  shares=tuple(float(s) for s in np.arange(1, m + 1)), min_grip=2.0,
                                  friction_coefficient=0.5, friction_facets=6, torque_limits=True)


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("m", [2, 3])
def test_update_writes_the_documented_rows(space, m):
    """``update``'s arrays (every family of rows, the external split, the squeeze basis) are what the class
    docstring says: the balance rows map the external split onto the load, the squeeze basis is internal, the
    grip rows hold the unit normals, the friction rows the pyramid's statement, the torque rows ``J_i^T`` within
    ``-tau_max - bias .. tau_max - bias``; the preferred split is the external one plus the desired squeeze."""
    k, p, n = K_OF[space], P_OF[space], K_OF[space] * m
    for seed in range(3):
        r, r0, w, normals, J, bias, tau_max = random_inputs(space, m, seed=100 * m + seed)
        pb = LoadDistributionProblem(config(space, m), space, m)
        pb.update(r, r0, w, normals=normals, jacobians=J, biases=bias, tau_max=tau_max)
        nf = 6 if space == "spatial" else 2
        dofs = [j.shape[1] for j in J]
        n_in = m + m * nf + sum(dofs)
        assert pb.M.shape == (k + n_in, n)
        np.testing.assert_array_equal(pb.M[:k], grasp_matrix(r, r0, space))
        np.testing.assert_array_equal(pb.lo[:k], w)
        np.testing.assert_array_equal(pb.hi[:k], w)
        np.testing.assert_array_equal(pb.E, internal_force_basis(r, space))
        assert np.array_equal(pb.F_pref, pb.external + pb.E @ pb.s_des)
        # Tolerances: |w| <= ~60 N and G W^-1 G^T is well conditioned here (contacts ~0.3 m apart, shares 1..3),
        # so the Cholesky solve is good to ~1e-13 relative; E's entries are O(1) and G's moment arms O(1) m, so
        # G E is zero to ~1e-15
        G, C = pb.M[:k], pb.M[k:]
        np.testing.assert_allclose(G @ pb.external, w, rtol=0, atol=1e-11 * np.abs(w).max())
        np.testing.assert_allclose(G @ pb.E, 0.0, atol=1e-13)
        nrm = normals / np.sqrt(np.einsum("ij,ij->i", normals, normals))[:, None]  # update's normalisation
        for i in range(m):
            np.testing.assert_allclose(C[i, k * i:k * i + p], nrm[i], rtol=0, atol=1e-15)
        np.testing.assert_array_equal(pb.lo[k:k + m], 2.0)
        want = np.zeros((m * nf, n))
        phi = 2.0 * np.pi * np.arange(nf) / nf
        mu_c = 0.5 * np.cos(np.pi / nf) if space == "spatial" else 0.5
        friction_rows(want, 0, nrm, k, nf, mu_c, np.cos(phi), np.sin(phi), space == "spatial")
        np.testing.assert_allclose(C[m:m + m * nf], want, rtol=0, atol=1e-15)
        np.testing.assert_array_equal(pb.hi[k + m:k + m + m * nf], 0.0)
        row = m + m * nf
        for i, Ji in enumerate(J):
            np.testing.assert_array_equal(C[row:row + dofs[i], k * i:k * (i + 1)], Ji.T)
            np.testing.assert_array_equal(pb.hi[k + row:k + row + dofs[i]], tau_max[i] - bias[i])
            np.testing.assert_array_equal(pb.lo[k + row:k + row + dofs[i]], -tau_max[i] - bias[i])
            row += dofs[i]


def test_helpers_take_lists_and_any_memory_order():
    """The helpers' arrays do not depend on the inputs' kind (lists, Fortran order)."""
    for space in ("spatial", "planar"):
        for m in (2, 3):
            r, r0, _, _, _, _, _ = random_inputs(space, m, seed=7 + m)
            np.testing.assert_array_equal(grasp_matrix(r.tolist(), r0, space), grasp_matrix(r, r0, space))
            np.testing.assert_array_equal(internal_force_basis(np.asfortranarray(r), space),
                                          internal_force_basis(r, space))


@pytest.mark.parametrize("space", ["spatial", "planar"])
@pytest.mark.parametrize("m", [1, 2, 4])
def test_helpers_against_the_analytic_grasp(space, m):
    """``grasp_matrix`` maps a pure force ``f`` at contact i to ``(f, (r_i - r_0) x f)`` (planar: the
    moment ``d_x f_z - d_z f_x``) and a pure moment to itself; ``internal_force_basis`` has unit
    columns ``+-t_ij`` on the force entries of pair (i, j) and ``G E = 0``."""
    rng = np.random.default_rng(40 + m)
    k, p = K_OF[space], P_OF[space]
    r0 = rng.normal(size=p)
    r = r0 + rng.normal(size=(m, p))
    G = grasp_matrix(r, r0, space)
    assert G.shape == (k, k * m)
    for i in range(m):
        f = rng.normal(size=p)
        F = np.zeros(k * m)
        F[k * i:k * i + p] = f
        d = r[i] - r0
        moment = np.cross(d, f) if space == "spatial" else np.array([d[0] * f[1] - d[1] * f[0]])
        # G @ F sums the same two products (and exact zeros) as the cross product, in another order:
        # entries O(1), so a few ulps, ~1e-15
        np.testing.assert_allclose(G @ F, np.concatenate([f, moment]), rtol=0, atol=1e-13)
        F[:] = 0.0
        mom = rng.normal(size=k - p)
        F[k * i + p:k * (i + 1)] = mom
        np.testing.assert_array_equal(G @ F, np.concatenate([np.zeros(p), mom]))
    E = internal_force_basis(r, space)
    assert E.shape == (k * m, m * (m - 1) // 2)
    col = 0
    for i in range(m):
        for j in range(i + 1, m):
            t = (r[j] - r[i]) / np.linalg.norm(r[j] - r[i])
            expected = np.zeros(k * m)
            expected[k * i:k * i + p] = t
            expected[k * j:k * j + p] = -t
            np.testing.assert_allclose(E[:, col], expected, rtol=0, atol=1e-15)
            col += 1
    np.testing.assert_allclose(G @ E, 0.0, atol=1e-14)  # sums of O(1) terms that cancel


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_coincident_contacts_name_the_pair(space):
    r = np.random.default_rng(3).normal(size=(3, P_OF[space]))
    r[2] = r[0]
    with pytest.raises(ScenarioError, match=r"r_contacts.*\(0, 2\).*distinct contact points"):
        internal_force_basis(r, space)
    pb = LoadDistributionProblem(LoadDistributionConfig(squeeze=5.0), space, 3)
    with pytest.raises(ScenarioError, match=r"r_contacts.*\(0, 2\).*distinct contact points"):
        pb.update(r, np.zeros(P_OF[space]), np.ones(K_OF[space]))
