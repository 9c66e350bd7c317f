"""The QP's contact inputs are written once (issue 10, Layout): the compiled core (coopctrl/core/qp_contact_model.h)
defines the contact normals and the torque-limit model; the compiled tick and the loaded start's wrappers
(:mod:`coopctrl.loop.qp_inputs`) call it. Here each is checked against an independent computation:
the normals against the frame's rotation, the torque model against each arm's own inverse dynamics with
the world angular-velocity Jacobian taken by finite differences of its forward kinematics. Every random
draw is seeded."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from coopctrl.loop.qp_inputs import TorqueModel, contact_normals, torque_model
from coopctrl.scenario import build, load_scenario
from plants.cooperative import ContactPoint
from plants.frames import rotation_zyx
from test_cli import REPO


def _normals(Y, spatial):
    """:func:`contact_normals` of the node poses ``Y`` (the plant and terms it reads, by name)."""
    plant = SimpleNamespace(space="spatial" if spatial else "planar", arm_count=Y.shape[0] - 1)
    return contact_normals(plant, SimpleNamespace(Y=Y))


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_normals_are_the_node_frames_approach_axis(space):
    """``n_i`` is the first column of ``R(A_{i+1})`` (spatial) or ``(cos th, sin th)`` (planar) on seeded random
    poses, angles over whole turns (the ZYX pitch too: the rotation is defined everywhere)."""
    rng = np.random.default_rng(1001 if space == "spatial" else 1002)
    spatial = space == "spatial"
    p = 6 if spatial else 3
    for m in (1, 2, 4):
        Y = np.ascontiguousarray(rng.uniform(-4.0, 4.0, size=(m + 1, p)))
        nrm = _normals(Y, spatial)
        if spatial:
            want = np.array([rotation_zyx(Y[i + 1, 3:6])[:, 0] for i in range(m)])
        else:
            want = np.column_stack((np.cos(Y[1:, 2]), np.sin(Y[1:, 2])))
        # the same rotation entries, then divided by a length within a few ulps of 1: a few ulps apart
        np.testing.assert_allclose(nrm, want, rtol=0, atol=1e-15)
        np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, rtol=0, atol=1e-15)


def _scene(name):
    scenario = load_scenario(REPO / "scenarios" / f"{name}.toml")
    plant = build.build_plant(scenario)
    return scenario, plant


def _random_state(scenario, plant, rng):
    """The unloaded state with every joint moved by ~0.05 rad and seeded joint and object rates."""
    x = np.array(build.unloaded_state(scenario), dtype=float)
    nz, p = plant.nz, plant.p
    x[:nz - p] += rng.normal(scale=0.05, size=nz - p)
    x[nz:] = rng.normal(scale=0.3, size=nz)
    return x


def _world_angular_jacobian(arm, q, h=1e-6):
    """``d omega_world / d dq`` by central differences of the node rotation: column c is the axial vector of
    ``dR/dq_c R^T``."""
    R = rotation_zyx(arm.pose(q)[3:6])
    out = np.empty((3, q.shape[0]))
    for c in range(q.shape[0]):
        e = np.zeros_like(q)
        e[c] = h
        dR = (rotation_zyx(arm.pose(q + e)[3:6]) - rotation_zyx(arm.pose(q - e)[3:6])) / (2.0 * h)
        Om = dR @ R.T
        out[:, c] = (Om[2, 1], Om[0, 2], Om[1, 0])
    return out


@pytest.mark.parametrize("name", ["heavy_payload_torque_limits", "spatial_three_arm_carry", "three_iiwa_tray",
                                  "contact_points_only"])
def test_torque_model_is_the_arms_inverse_dynamics(name):
    """``Jg_i^T F_i + bias_i`` equals arm i's joint torques from its own model (``arm.terms``: ``H``, ``h``,
    ``J``, ``dJ/dt dq``) for the joint acceleration that tracks the nominal node acceleration (``J^-1`` for
    the square planar 3R and Puma arms, the inertia-weighted ``J^#`` for the 7-joint iiwa), plus the node's
    own ``W a + w_free``, with the contact wrench mapped through the world twist Jacobian (its angular rows
    by finite differences of the forward kinematics); a contact point carries ``F + W a + w_free``. Seeded
    random states and accelerations."""
    scenario, plant = _scene(name)
    rng = np.random.default_rng(sum(map(ord, name)))
    spatial = plant.space == "spatial"
    p, nz = plant.p, plant.nz
    for _ in range(2):
        x = _random_state(scenario, plant, rng)
        terms = plant.control_terms(x)
        ddYn = rng.normal(scale=1.0, size=(plant.arm_count + 1, p))
        jac, bias = torque_model(plant, terms, ddYn)
        for i, arm in enumerate(plant.arms):
            k = i + 1
            F = rng.normal(scale=50.0, size=p)
            node = terms.W[k] @ ddYn[k] + terms.w_free[k]
            if isinstance(arm, ContactPoint):
                assert np.array_equal(jac[i], np.eye(p))
                np.testing.assert_allclose(bias[i], node, rtol=1e-14, atol=1e-14 * np.abs(node).max())
                continue
            sl = plant.q_slice(i)
            q, dq = x[sl], x[nz:][sl]
            at = arm.terms(q, dq)
            H, h, J, Jdq = at.H, at.h, at.J, at.Jdq
            n = arm.dof
            rhs = ddYn[k] - Jdq
            if n == p:
                qdd = np.linalg.solve(J, rhs)
            else:
                N = H + J.T @ terms.W[k] @ J
                X = np.linalg.solve(N, J.T)
                qdd = X @ np.linalg.solve(J @ X, rhs)
                assert np.linalg.cond(N) < 1e6
            # well-conditioned draws, so LAPACK's and the kernel's LU agree to ~cond * 1e-16
            assert np.linalg.cond(J @ J.T) < 1e6
            np.testing.assert_allclose(J @ qdd, rhs, rtol=0, atol=1e-9 * (1.0 + np.abs(rhs).max()))
            bias_ref = H @ qdd + h + J.T @ node
            Jg_ref = J.copy()
            if spatial:
                Jg_ref[3:] = _world_angular_jacobian(arm, q)
            assert jac[i].shape == (p, n) and bias[i].shape == (n,)
            # linear rows: the plant's Jacobian and the arm's, the same kinematics (rounding apart)
            np.testing.assert_allclose(jac[i][:3 if spatial else p], Jg_ref[:3 if spatial else p], rtol=0, atol=1e-12)
            # angular rows [-]: central differences with h = 1e-6 rad, truncation ~h^2 and rounding ~1e-16 / h
            np.testing.assert_allclose(jac[i], Jg_ref, rtol=0, atol=1e-8)
            # bias [N m]: the same formula at qdd from two backward-stable solves of systems with
            # cond < 1e6 (checked above; J J^T ~50 to 400, N ~2e3 in these draws): ~1e-10 relative at worst
            np.testing.assert_allclose(bias[i], bias_ref, rtol=0, atol=1e-9 * (1.0 + np.abs(bias_ref).max()))
            tau_ref = bias_ref + Jg_ref.T @ F
            # torques [N m]: |F| ~ 50 N times the angular rows' 1e-8 above, against torques of ~10 to 100 N m
            np.testing.assert_allclose(jac[i].T @ F + bias[i], tau_ref, rtol=0,
                                       atol=1e-7 * (1.0 + np.abs(tau_ref).max()))


def test_the_wrappers_take_any_memory_order():
    """``contact_normals`` and ``torque_model`` give the same numbers from plant terms and from a non-contiguous
    ``ddYn`` as from C-ordered copies."""
    for name in ("heavy_payload_torque_limits", "contact_points_only", "three_iiwa_tray"):
        scenario, plant = _scene(name)
        terms = plant.control_terms(build.unloaded_state(scenario))
        np.testing.assert_array_equal(contact_normals(plant, terms),
                                      contact_normals(plant, SimpleNamespace(Y=np.ascontiguousarray(terms.Y))))
        ddYn = np.zeros((plant.arm_count + 1, plant.p)) + 1.0
        jacobians, biases = torque_model(plant, terms, np.asfortranarray(ddYn))
        want_j, want_b = torque_model(plant, terms, ddYn)
        for i in range(plant.arm_count):
            np.testing.assert_array_equal(jacobians[i], want_j[i])
            np.testing.assert_array_equal(biases[i], want_b[i])


@pytest.mark.parametrize("name", ["three_iiwa_tray", "contact_points_only"])
def test_torque_model_workspace_gives_the_same_rows_call_after_call(name):
    """:class:`TorqueModel` (pre-flight's, one workspace) returns at each call exactly :func:`torque_model`'s
    rows at that call's terms (the same kernel on the same inputs: bit for bit), as views that the next call
    overwrites: the 7-joint iiwa (a redundant arm) and contact points. Seeded random states."""
    scenario, plant = _scene(name)
    rng = np.random.default_rng(7)
    model = TorqueModel(plant)
    first = None
    for _ in range(3):
        terms = plant.control_terms(_random_state(scenario, plant, rng))
        ddYn = rng.normal(scale=1.0, size=(plant.arm_count + 1, plant.p))
        jac, bias = model(terms, ddYn)
        jac_ref, bias_ref = torque_model(plant, terms, ddYn)
        for i in range(plant.arm_count):
            assert np.array_equal(jac[i], jac_ref[i]) and np.array_equal(bias[i], bias_ref[i])
        if first is None:
            first = [b.copy() for b in bias], bias
    assert first[1] is bias  # the same views, refilled
    if name == "three_iiwa_tray":  # random states: the bias torques moved
        assert not all(np.array_equal(a, b) for a, b in zip(first[0], bias))
