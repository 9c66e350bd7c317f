"""coopctrl.controllers.leader_law: the user's leader law runs compiled inside the tick and changes the
motion as its gains predict."""

from __future__ import annotations

import math

import numpy as np
import pytest

import coopctrl
from coopctrl.controllers.leader_law import LeaderLaw, object_impedance
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

DURATION = 0.6  # [s]: three periods of the slower impedance below


@pytest.fixture(scope="module")
def lift():
    scenario = coopctrl.load_scenario("planar_two_arm_lift", {"simulation.duration": DURATION})
    return scenario, build.initial_state(scenario)


def test_the_impedance_law_with_the_leader_gains_is_the_shipped_law_bit_for_bit(lift):
    """M = 1, D = Kd, K = Kp: the impedance law's arithmetic is the computed torque's, so the record is
    identical bit for bit: the law the user passes is what the compiled tick runs."""
    scenario, x0 = lift
    plain = closed_loop(scenario)
    Kp, Kd = plain.leader.Kp, plain.leader.Kd
    a = plain.run(x0, DURATION)
    b = closed_loop(scenario, leader_law=object_impedance(1.0, Kd, Kp, 1.0, Kd, Kp)).run(x0, DURATION)
    assert a["status"] == b["status"] == "ok"
    np.testing.assert_array_equal(a["x"], b["x"])
    np.testing.assert_array_equal(a["tau"], b["tau"])
    soft = closed_loop(scenario, leader_law=object_impedance(1.0, 0.5 * Kd, 0.25 * Kp, 1.0, Kd, Kp)).run(x0, DURATION)
    assert np.abs(soft["x"] - a["x"]).max() > 0.0  # another impedance, another motion


@pytest.mark.parametrize("stiffness, zeta", [(3200.0, 0.7), (7200.0, 1.0)])
def test_a_perturbed_leader_node_rings_as_its_impedance_predicts(stiffness, zeta):
    """The leader's joint 0 starts 1e-4 rad off (its node about 6e-5 m off its target). With the law
    ``M e'' + D e' + K e = 0`` (M = 2 kg, K = ``stiffness``: omega = 40 or 60 rad/s, damping ratio
    ``zeta``) the node's deviation from the unperturbed run follows the free response
    ``g(t) = exp(-zeta omega t) (cos(omega_d t) + zeta omega / omega_d sin(omega_d t))`` (critically
    damped: ``exp(-omega t) (1 + omega t)``) of its initial deviation. The computed torque holds the
    period's first contact wrench over the period while the grasp springs move: the deviation from
    ``g`` shrinks with the period (measured at omega = 40 rad/s: 12 % of the initial deviation at
    T = 1 ms, 2.5 % at 0.2 ms), so this runs at T = 0.2 ms and allows 5 %."""
    scenario = coopctrl.load_scenario("planar_two_arm_lift", {"simulation.duration": 0.15,
                                                              "simulation.control_period": 2e-4})
    x0 = build.initial_state(scenario)
    M, K = 2.0, stiffness
    omega = math.sqrt(K / M)
    D = 2.0 * zeta * math.sqrt(K * M)
    loop = closed_loop(scenario, leader_law=object_impedance(M, D, K, M, D, K))
    i = loop.leader.index
    x1 = x0.copy()
    x1[loop.plant.q_slice(i).start] += 1e-4
    base, pert = loop.run(x0, 0.15), loop.run(x1, 0.15)
    assert base["status"] == pert["status"] == "ok"
    d = pert["r_contacts"][:, i] - base["r_contacts"][:, i]  # (N, 2) [m]
    d0 = d[0]
    assert np.linalg.norm(d0) > 1e-5
    t = base["t"]
    wd = omega * math.sqrt(max(1.0 - zeta**2, 0.0))
    if wd > 0.0:
        g = np.exp(-zeta * omega * t) * (np.cos(wd * t) + zeta * omega / wd * np.sin(wd * t))
    else:
        g = np.exp(-omega * t) * (1.0 + omega * t)
    err = np.linalg.norm(d - g[:, None] * d0[None, :], axis=1).max()
    assert err <= 0.05 * np.linalg.norm(d0)


def test_a_law_of_the_wrong_shape_is_refused_by_name():
    with pytest.raises(TypeError, match="expected 7"):
        LeaderLaw(lambda err, a_cmd: None, (1.0,))
    with pytest.raises(ValueError, match="finite"):
        LeaderLaw(object_impedance(1, 1, 1, 1, 1, 1).function, (1.0, math.nan))
    with pytest.raises(ValueError, match="mass > 0"):
        object_impedance(0.0, 1.0, 1.0, 1.0, 1.0, 1.0)
    scenario = coopctrl.load_scenario("planar_two_arm_lift", {"simulation.duration": 0.01})
    with pytest.raises(TypeError, match="leader_law = "):
        closed_loop(scenario, leader_law=lambda *a: None)
