"""Tests of coopctrl.load_distribution (seeded random scenes, spatial and planar, m = 2, 3)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coopctrl.errors import InfeasibleLoad, ScenarioError
from coopctrl.load_distribution import (
    LoadDistribution,
    LoadDistributionConfig,
    LoadSplit,
    grasp_matrix,
    internal_force_basis,
)

SPACES = ["spatial", "planar"]
ARMS = [2, 3]
K_OF = {"spatial": 6, "planar": 3}
P_OF = {"spatial": 3, "planar": 2}
GRAVITY = 9.81


def weight(space: str, mass: float) -> np.ndarray:
    """External load of a resting object of ``mass`` [kg]: the arms must push up."""
    w = np.zeros(K_OF[space])
    w[P_OF[space] - 1] = mass * GRAVITY
    return w


def ring_contacts(space: str, m: int, radius: float = 0.25) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Contacts around the object MC (origin): on a horizontal circle (spatial) or at +-x (planar,
    m = 2; for m = 3 one extra contact on top). Returns contacts, inward normals, r_0."""
    p = P_OF[space]
    r0 = np.zeros(p)
    if space == "spatial":
        ang = 2 * np.pi * np.arange(m) / m
        r = radius * np.stack([np.cos(ang), np.sin(ang), np.zeros(m)], axis=1)
    else:
        pts = [(radius, 0.0), (-radius, 0.0), (0.0, radius)][:m]
        r = np.array(pts)
    normals = -r / np.linalg.norm(r, axis=1, keepdims=True)
    return r, normals, r0


def random_scene(space: str, m: int, seed: int):
    rng = np.random.default_rng(seed)
    p = P_OF[space]
    r0 = rng.normal(size=p) * 0.1
    r = r0 + rng.normal(size=(m, p)) * 0.3
    w = rng.normal(size=K_OF[space]) * 20.0
    return rng, r, r0, w


def weighted_pinv_split(G: np.ndarray, W_diag: np.ndarray, w: np.ndarray) -> np.ndarray:
    Wi = np.diag(1.0 / W_diag)
    return Wi @ G.T @ np.linalg.solve(G @ Wi @ G.T, w)


def random_block_stiffness(rng, m: int, k: int) -> np.ndarray:
    K = np.zeros((k * m, k * m))
    for i in range(m):
        B = rng.normal(size=(k, k))
        K[k * i:k * (i + 1), k * i:k * (i + 1)] = B @ B.T + k * np.eye(k) * (1 + i)
    return K


# --------------------------------------------------------------------------- grasp matrix
@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", [2, 3, 4])
def test_internal_basis_in_null_space_of_G(space, m):
    _, r, r0, _ = random_scene(space, m, seed=10 + m)
    G = grasp_matrix(r, r0, space)
    E = internal_force_basis(r, space)
    assert G.shape == (K_OF[space], K_OF[space] * m)
    assert E.shape == (K_OF[space] * m, m * (m - 1) // 2)
    np.testing.assert_allclose(G @ E, 0.0, atol=1e-12)
    # positive squeeze pushes contact 0 toward contact 1
    p = P_OF[space]
    t01 = (r[1] - r[0]) / np.linalg.norm(r[1] - r[0])
    np.testing.assert_allclose(E[:p, 0], t01)
    np.testing.assert_allclose(E[K_OF[space]:K_OF[space] + p, 0], -t01)


def test_grasp_matrix_moments_match_cross_product():
    rng = np.random.default_rng(1)
    r, r0 = rng.normal(size=(2, 3)), rng.normal(size=3)
    F = rng.normal(size=12)
    G = grasp_matrix(r, r0, "spatial")
    f, n = F.reshape(2, 6)[:, :3], F.reshape(2, 6)[:, 3:]
    expected = np.concatenate([f.sum(0), sum(np.cross(r[i] - r0, f[i]) + n[i] for i in range(2))])
    np.testing.assert_allclose(G @ F, expected, atol=1e-12)


def test_planar_grasp_matrix_sign_convention():
    # a contact at +x pushing up (+z) turns the object from +x toward +z: positive moment
    G = grasp_matrix(np.array([[1.0, 0.0]]), np.zeros(2), "planar")
    np.testing.assert_allclose(G @ np.array([0.0, 1.0, 0.0]), [0.0, 1.0, 1.0])
    G = grasp_matrix(np.array([[0.0, 1.0]]), np.zeros(2), "planar")
    np.testing.assert_allclose(G @ np.array([1.0, 0.0, 0.0]), [1.0, 0.0, -1.0])


# --------------------------------------------------------------------------- unconstrained split
@pytest.mark.parametrize("space", SPACES)
def test_symmetric_two_arm_grasp_shares_equally(space):
    r, _, r0 = ring_contacts(space, 2)
    ld = LoadDistribution(LoadDistributionConfig(), space, 2)
    s = ld.solve(r, r0, weight(space, 10.0))
    assert s.status == "solved" and not s.held
    np.testing.assert_allclose(s.F[0], s.F[1], atol=1e-9)
    np.testing.assert_allclose(s.F.sum(0)[:P_OF[space]], weight(space, 10.0)[:P_OF[space]], atol=1e-9)
    np.testing.assert_allclose(s.squeeze, 0.0, atol=1e-9)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
@pytest.mark.parametrize("shares", [None, "random"])
def test_balance_null_space_and_closed_form(space, m, shares):
    rng0 = np.random.default_rng(100 + m)
    sh = None if shares is None else tuple(rng0.uniform(0.5, 2.0, size=m))
    cfg = LoadDistributionConfig(shares=sh, force_weight=1.0, moment_weight=4.0)
    ld = LoadDistribution(cfg, space, m)
    for seed in range(5):
        _, r, r0, w = random_scene(space, m, seed)
        s = ld.solve(r, r0, w)
        G = grasp_matrix(r, r0, space)
        F = s.F.ravel()
        assert np.linalg.norm(G @ F - w) <= 1e-8 * np.linalg.norm(w)
        assert np.linalg.norm(G @ s.internal.ravel()) <= 1e-8 * max(np.linalg.norm(F), 1.0)
        k, p = K_OF[space], P_OF[space]
        W_diag = np.concatenate([np.r_[[1.0] * p, [4.0] * (k - p)] / (1.0 if sh is None else sh[i]) for i in range(m)])
        expected = weighted_pinv_split(G, W_diag, w)
        np.testing.assert_allclose(F, expected, atol=1e-7 * (1 + np.abs(expected).max()))
        np.testing.assert_allclose(s.external.ravel(), expected, atol=1e-9 * (1 + np.abs(expected).max()))


def test_leader_share_carries_more():
    r, _, r0 = ring_contacts("spatial", 2)
    ld = LoadDistribution(LoadDistributionConfig(shares=(2.0, 1.0)), "spatial", 2)
    s = ld.solve(r, r0, weight("spatial", 3.0))
    assert s.F[0, 2] > 1.5 * s.F[1, 2]


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
def test_elastic_split_matches_closed_form(space, m):
    rng, r, r0, w = random_scene(space, m, seed=7)
    K = random_block_stiffness(rng, m, K_OF[space])
    ld = LoadDistribution(LoadDistributionConfig(split="elastic"), space, m)
    s = ld.solve(r, r0, w, K=K)
    G = grasp_matrix(r, r0, space)
    expected = K @ G.T @ np.linalg.solve(G @ K @ G.T, w)
    np.testing.assert_allclose(s.F.ravel(), expected, atol=1e-7 * (1 + np.abs(expected).max()))
    with pytest.raises(ScenarioError, match="K"):
        ld.solve(r, r0, w)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
def test_desired_squeeze_is_reproduced(space, m):
    _, r, r0, w = random_scene(space, m, seed=3)
    npairs = m * (m - 1) // 2
    s_des = tuple(np.linspace(5.0, 15.0, npairs))
    s = LoadDistribution(LoadDistributionConfig(squeeze=s_des), space, m).solve(r, r0, w)
    np.testing.assert_allclose(s.squeeze, s_des, atol=1e-6)
    G = grasp_matrix(r, r0, space)
    assert np.linalg.norm(G @ s.F.ravel() - w) <= 1e-8 * np.linalg.norm(w)
    # one number for every pair
    s = LoadDistribution(LoadDistributionConfig(squeeze=12.5), space, m).solve(r, r0, w)
    np.testing.assert_allclose(s.squeeze, 12.5, atol=1e-6)


# --------------------------------------------------------------------------- inequalities
def torque_scene(space: str, m: int, seed: int, margin: float = 1.0):
    """Square random Jacobians and biases; limits set from a feasible squeezed split so that the
    preferred split violates them (torque limits active) while a feasible split exists."""
    rng, r, r0, w = random_scene(space, m, seed)
    k = K_OF[space]
    J = [rng.normal(size=(k, k)) * 0.5 for _ in range(m)]
    bias = [rng.normal(size=k) * 2.0 for _ in range(m)]
    G = grasp_matrix(r, r0, space)
    F_pref = weighted_pinv_split(G, np.ones(k * m), w)
    null = np.linalg.svd(G)[2][k:].T
    F_alt = F_pref + null @ rng.normal(size=null.shape[1]) * 10.0
    tau_alt = [J[i].T @ F_alt[k * i:k * (i + 1)] + bias[i] for i in range(m)]
    tau_max = [np.abs(t) * margin + 1e-3 for t in tau_alt]
    return r, r0, w, J, bias, tau_max, F_pref


def torques(F, J, bias):
    return [J[i].T @ F[i] + bias[i] for i in range(len(J))]


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
def test_torque_limits_active_and_respected(space, m):
    cfg = LoadDistributionConfig(torque_limits=True)
    for seed in range(20):
        r, r0, w, J, bias, tau_max, F_pref = torque_scene(space, m, seed)
        k = K_OF[space]
        pref_viol = max(np.max(np.abs(J[i].T @ F_pref[k * i:k * (i + 1)] + bias[i]) - tau_max[i]) for i in range(m))
        if pref_viol > 1e-3:
            break
    else:  # pragma: no cover
        pytest.fail("no seed makes the torque limits active")
    s = LoadDistribution(cfg, space, m).solve(r, r0, w, jacobians=J, biases=bias, tau_max=tau_max)
    assert s.status == "solved"
    assert "torque_limits" in s.binding
    for i, tau in enumerate(torques(s.F, J, bias)):
        assert np.all(np.abs(tau) <= tau_max[i] + 1e-6)
    G = grasp_matrix(r, r0, space)
    assert np.linalg.norm(G @ s.F.ravel() - w) <= 1e-8 * np.linalg.norm(w)
    assert np.linalg.norm(G @ s.internal.ravel()) <= 1e-8 * np.linalg.norm(s.F)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
def test_min_grip_respected_when_active(space, m):
    r, normals, r0 = ring_contacts(space, m)
    w = weight(space, 5.0)
    cfg = LoadDistributionConfig(min_grip=20.0)
    s = LoadDistribution(cfg, space, m).solve(r, r0, w, normals=normals)
    p = P_OF[space]
    grip = np.einsum("ij,ij->i", s.F[:, :p], normals)
    assert np.all(grip >= 20.0 - 1e-6)
    assert np.isclose(grip.min(), 20.0, atol=1e-6)  # active
    assert "min_grip" in s.binding
    G = grasp_matrix(r, r0, space)
    assert np.linalg.norm(G @ s.F.ravel() - w) <= 1e-8 * np.linalg.norm(w)
    if m == 2:  # symmetric: a pure squeeze of exactly the minimum grip
        np.testing.assert_allclose(s.squeeze, [20.0], atol=1e-6)


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
@pytest.mark.parametrize("facets", [4, 8])
def test_friction_pyramid_respected_when_active(space, m, facets):
    r, normals, r0 = ring_contacts(space, m)
    w = weight(space, 5.0)
    mu = 0.4
    cfg = LoadDistributionConfig(friction_coefficient=mu, friction_facets=facets)
    s = LoadDistribution(cfg, space, m).solve(r, r0, w, normals=normals)
    assert s.status == "solved" and "friction" in s.binding
    p = P_OF[space]
    f = s.F[:, :p]
    fn = np.einsum("ij,ij->i", f, normals)
    ft = np.linalg.norm(f - fn[:, None] * normals, axis=1)
    assert np.all(fn >= -1e-6)
    assert np.all(ft <= mu * fn + 1e-6)  # inscribed pyramid: inside the true cone
    if space == "spatial":  # on a facet of the pyramid, not strictly inside
        assert np.any(ft >= mu * math.cos(math.pi / facets) * fn - 1e-6)
    G = grasp_matrix(r, r0, space)
    assert np.linalg.norm(G @ s.F.ravel() - w) <= 1e-8 * np.linalg.norm(w)


# --------------------------------------------------------------------------- failure policy
@pytest.mark.parametrize("space", SPACES)
def test_infeasible_first_solve_raises(space):
    r, r0, w, J, bias, tau_max, _ = torque_scene(space, 2, seed=0)
    ld = LoadDistribution(LoadDistributionConfig(torque_limits=True), space, 2)
    with pytest.raises(InfeasibleLoad) as info:
        ld.solve(r, r0, w * 1e4, jacobians=J, biases=bias, tau_max=tau_max)
    assert info.value.status == "infeasible"
    assert info.value.binding  # names the violated families
    assert set(info.value.binding) <= {"balance", "torque_limits"}


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("solver", ["proxsuite", "daqp", "compiled"])
def test_hold_last_split_then_raise(space, solver):
    r, r0, w, J, bias, tau_max, _ = torque_scene(space, 2, seed=0)
    cfg = LoadDistributionConfig(torque_limits=True, max_consecutive_failures=3, solver=solver)
    ld = LoadDistribution(cfg, space, 2)
    good = ld.solve(r, r0, w, jacobians=J, biases=bias, tau_max=tau_max)
    assert good.status == "solved" and not good.held
    for _ in range(2):
        held = ld.solve(r, r0, w * 1e4, jacobians=J, biases=bias, tau_max=tau_max)
        assert held.held and held.status == "infeasible"
        np.testing.assert_array_equal(held.F, good.F)
    # recovery resets the count
    again = ld.solve(r, r0, w, jacobians=J, biases=bias, tau_max=tau_max)
    assert again.status == "solved" and not again.held
    np.testing.assert_allclose(again.F, good.F, atol=1e-6)
    for _ in range(2):
        assert ld.solve(r, r0, w * 1e4, jacobians=J, biases=bias, tau_max=tau_max).held
    with pytest.raises(InfeasibleLoad, match="infeasible"):
        ld.solve(r, r0, w * 1e4, jacobians=J, biases=bias, tau_max=tau_max)
    st = ld.statistics
    assert st["status"] == ["solved", "infeasible", "infeasible", "solved", "infeasible", "infeasible", "infeasible"]
    assert st["held"] == [False, True, True, False, True, True, True]
    assert len(st["solve_time_s"]) == 7 and all(t > 0 for t in st["solve_time_s"])


# --------------------------------------------------------------------------- backends
@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", ARMS)
@pytest.mark.parametrize("backend", ["daqp", "quadprog", "compiled"])
@pytest.mark.parametrize("family", ["torque_limits", "grip_and_friction"])
def test_backends_agree(space, m, backend, family):
    if family == "torque_limits":
        r, r0, w, J, bias, tau_max, _ = torque_scene(space, m, seed=4)
        kwargs = dict(jacobians=J, biases=bias, tau_max=tau_max)
        base = dict(torque_limits=True)
    else:
        r, normals, r0 = ring_contacts(space, m)
        w = weight(space, 5.0) + np.r_[[3.0] * P_OF[space], [0.5] * (K_OF[space] - P_OF[space])]
        kwargs = dict(normals=normals)
        base = dict(min_grip=15.0, friction_coefficient=0.5)
    a = LoadDistribution(LoadDistributionConfig(**base), space, m).solve(r, r0, w, **kwargs)
    b = LoadDistribution(LoadDistributionConfig(solver=backend, **base), space, m).solve(r, r0, w, **kwargs)
    assert a.status == b.status == "solved"
    assert a.binding  # some inequality is active
    np.testing.assert_allclose(a.F, b.F, atol=1e-6)
    assert a.binding == b.binding


def test_warm_started_sequence_matches_cold_solves():
    """The persistent proxsuite QP, updated in place along a trajectory, equals fresh solves."""
    space, m = "spatial", 3
    warm = LoadDistribution(LoadDistributionConfig(torque_limits=True), space, m)
    for seed in range(8):
        r, r0, w, J, bias, tau_max, _ = torque_scene(space, m, seed)
        a = warm.solve(r, r0, w, jacobians=J, biases=bias, tau_max=tau_max)
        b = LoadDistribution(LoadDistributionConfig(torque_limits=True, solver="daqp"), space, m).solve(
            r, r0, w, jacobians=J, biases=bias, tau_max=tau_max
        )
        np.testing.assert_allclose(a.F, b.F, atol=1e-6)


# --------------------------------------------------------------------------- configuration
def test_default_config_is_valid():
    cfg = LoadDistributionConfig()
    assert cfg.solver == "proxsuite" and cfg.eps_abs == 1e-9 and cfg.inequality_families == ()


@pytest.mark.parametrize(
    "field, value",
    [
        ("split", "lsq"),
        ("shares", (1.0, -1.0)),
        ("force_weight", 0.0),
        ("moment_weight", float("nan")),
        ("squeeze", (1.0, "a")),
        ("min_grip", -1.0),
        ("friction_coefficient", 0.0),
        ("friction_facets", 2),
        ("torque_limits", 1),
        ("eps_abs", -1e-9),
        ("max_consecutive_failures", 0),
    ],
)
def test_config_rejects_bad_fields(field, value):
    with pytest.raises(ScenarioError, match=field) as info:
        LoadDistributionConfig(**{field: value})
    assert info.value.path.startswith(field)


def test_unknown_solver_says_how_to_install():
    with pytest.raises(ScenarioError, match=r"pip install qpsolvers\[") as info:
        LoadDistributionConfig(solver="no_such_solver")
    assert "daqp" in str(info.value)


def test_shape_errors_name_the_input():
    ld = LoadDistribution(LoadDistributionConfig(shares=(1.0, 1.0)), "spatial", 2)
    with pytest.raises(ScenarioError, match="r_contacts"):
        ld.solve(np.zeros((3, 3)), np.zeros(3), np.zeros(6))
    with pytest.raises(ScenarioError, match="shares"):
        LoadDistribution(LoadDistributionConfig(shares=(1.0, 1.0)), "spatial", 3)
    with pytest.raises(ScenarioError, match="normals"):
        LoadDistribution(LoadDistributionConfig(min_grip=1.0), "spatial", 2).solve(
            np.eye(3)[:2], np.zeros(3), np.ones(6)
        )


def test_load_split_is_frozen():
    r, _, r0 = ring_contacts("planar", 2)
    s = LoadDistribution(LoadDistributionConfig(), "planar", 2).solve(r, r0, weight("planar", 1.0))
    assert isinstance(s, LoadSplit)
    with pytest.raises(ValueError):
        s.F[0, 0] = 1.0
    with pytest.raises(AttributeError):
        s.status = "x"
