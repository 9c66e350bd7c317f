"""Redundancy resolution of 7-joint arms (issue 13): the null-space projector, the computed
torque of a redundant arm, and inverse kinematics with redundancy and joint limits.

Tolerances: the identities below are exact algebra evaluated in double precision on 7x7 and
6x6 systems with condition numbers below ~1e4, so 1e-9 relative leaves a wide margin over
rounding (observed ~1e-13).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from coopctrl.controllers.computed_torque import node_computed_torque
from coopctrl.scenario import load_scenario
from coopctrl.scenario.build import initial_state
from coopctrl.simulator import closed_loop
from plants.arms import iiwa14, panda
from plants.errors import UnreachablePoseError

SCENES = Path(__file__).resolve().parent.parent / "scenarios"
REL = 1e-9


@pytest.fixture(scope="module")
def loop():
    scenario = load_scenario(SCENES / "two_panda_carry.toml")
    cl = closed_loop(scenario)
    x = initial_state(scenario)
    # move off rest, seeded, so that Coriolis terms and the posture task are non-zero
    rng = np.random.default_rng(7)
    nz = cl.plant.nz
    x[nz:] += rng.normal(0.0, 0.05, nz)
    return cl, x


def _node_acceleration(plant, x, tau, i):
    dx = plant.rhs(0.0, x, tau)
    nz = plant.nz
    terms = plant.control_terms(x)
    n = plant.arms[i].dof
    return terms.J[i, :, :n] @ dx[nz:][plant.q_slice(i)] + terms.Jdq[i], dx[nz:][plant.q_slice(i)], dx[2 * nz - 6:]


def _projector(terms, i, n):
    """``P^T = I - J^T J^{#T}`` with ``J^# = N^-1 J^T (J N^-1 J^T)^-1``, ``N = H + J^T W J``."""
    H, J, W = terms.H[i, :n, :n], terms.J[i, :, :n], terms.W[i + 1]
    N = H + J.T @ W @ J
    Ni = np.linalg.inv(N)
    J_sharp = Ni @ J.T @ np.linalg.inv(J @ Ni @ J.T)
    return np.eye(n) - J.T @ J_sharp.T


def test_null_space_torque_does_not_accelerate_the_node(loop):
    cl, x = loop
    plant = cl.plant
    terms = plant.control_terms(x)
    i, n = 0, plant.arms[0].dof
    assert n == 7
    rng = np.random.default_rng(11)
    tau = rng.normal(0.0, 5.0, plant.input_size)
    tau_r = rng.normal(0.0, 5.0, n)
    PT = _projector(terms, i, n)
    tau2 = tau.copy()
    tau2[plant.q_slice(i)] += PT @ tau_r
    a1, qdd1, obj1 = _node_acceleration(plant, x, tau, i)
    a2, qdd2, obj2 = _node_acceleration(plant, x, tau2, i)
    # the same torque unprojected moves the node: the scale the difference is measured against
    tau3 = tau.copy()
    tau3[plant.q_slice(i)] += tau_r
    a3 = _node_acceleration(plant, x, tau3, i)[0]
    scale = np.linalg.norm(a3 - a1)
    assert scale > 1e-2
    assert np.linalg.norm(a2 - a1) <= REL * scale
    assert np.linalg.norm(obj2 - obj1) <= REL * scale
    assert np.linalg.norm(qdd2 - qdd1) > 1e-3 * np.linalg.norm(qdd1)  # the joints do move


def test_redundant_computed_torque_gives_the_commanded_node_acceleration(loop):
    cl, x = loop
    plant = cl.plant
    terms = plant.control_terms(x)
    i = cl.leader.index
    a_cmd = np.array([0.3, -0.2, 0.5, 0.1, -0.4, 0.2])
    tau = np.zeros(plant.input_size)
    tau_posture = cl.leader.posture.torque(terms)
    assert np.linalg.norm(tau_posture) > 0.0
    tau[plant.q_slice(i)] = node_computed_torque(plant, terms, i, a_cmd, tau_posture)
    a = _node_acceleration(plant, x, tau, i)[0]
    assert np.linalg.norm(a - a_cmd) <= REL * np.linalg.norm(a_cmd)


def test_kernel_matches_the_stated_law(loop):
    cl, x = loop
    plant = cl.plant
    terms = plant.control_terms(x)
    i, n = 1, plant.arms[1].dof
    H, h, J, W = terms.H[i, :n, :n], terms.h[i, :n], np.ascontiguousarray(terms.J[i, :, :n]), terms.W[i + 1]
    rng = np.random.default_rng(5)
    a = rng.normal(size=6)
    tau0 = rng.normal(size=n)
    N = H + J.T @ W @ J
    Ni = np.linalg.inv(N)
    J_sharp = Ni @ J.T @ np.linalg.inv(J @ Ni @ J.T)
    qdd = J_sharp @ (a - terms.Jdq[i])
    expected = H @ qdd + h + J.T @ (W @ a + terms.w_free[i + 1] + terms.S[i + 1]) + (np.eye(n) - J.T @ J_sharp.T) @ tau0
    tau = node_computed_torque(plant, terms, i, a, tau0)  # the law of the compiled core
    assert np.linalg.norm(tau - expected) <= REL * np.linalg.norm(expected)


@pytest.mark.parametrize("make, target", [
    (panda, [0.45, 0.1, 0.35, 0.2, 0.8, 3.0]),
    (iiwa14, [0.55, -0.1, 0.4, -0.2, 1.2, 0.1]),
])
def test_redundant_ik_within_limits_nearest_to_rest(make, target):
    arm = make()
    q = arm.inverse_kinematics(target)
    assert np.all(q >= arm.q_limits[:, 0]) and np.all(q <= arm.q_limits[:, 1])
    T, Jg = arm.tip_transform(q)
    assert np.linalg.norm(arm.pose(q)[:3] - target[:3]) <= 1e-9
    # nearest to the rest posture on the self-motion manifold: no null-space component left
    P = np.eye(arm.dof) - np.linalg.pinv(Jg) @ Jg
    assert np.linalg.norm(P @ (arm.rest_posture() - q)) <= 1e-6


def test_redundant_ik_reports_unreachable():
    with pytest.raises(UnreachablePoseError):
        panda().inverse_kinematics([2.0, 0.0, 0.3, 0.0, 0.0, 0.0], seeds=2)
