"""The control laws of one tick (coopctrl/core/control_laws.h, bound in ``coopctrl._core``): written once, in the
compiled core, called by the loop's tick and by the Python controllers.

Issue 18: ``LeaderController.torque`` and ``FollowerForceController.torque`` were a second copy of the
laws the compiled loop runs, and editing them changed nothing. They now call the compiled functions, so
these tests check the functions against independent references (numpy formulas written here, the plant's
own dynamics) and check that the Python controllers give, bit for bit, what a loop run applied. The leader's
target ``Y_nominal + increment + offset`` has no binding of its own: the loop's record checks it
(:func:`test_leader_torque_is_what_the_loop_applied`). The core's laws were checked bit for bit against the
numba kernels they replaced when they were ported; ``tests/golden`` locks the loop's numbers since.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from coopctrl import _core, load_scenario
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop
from plants.cooperative.loaded_state import nominal_node_motion

SCENES = Path(__file__).resolve().parent.parent / "scenarios"

#: Relative agreement of a compiled law with its numpy formula: the same few additions and products in a
#: possibly different order, on numbers of order one: rounding gives about 1e-16 relative; a wrong sign or
#: term gives order one.
REL = 1e-12


@pytest.fixture(scope="module")
def planar():
    """The planar lift, 0.05 s: its loop, initial state and record (noise free, no probes)."""
    scenario = load_scenario(SCENES / "planar_two_arm_lift.toml", {"simulation.duration": 0.05})
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    rec = loop.run(x0, 0.05)
    assert rec["status"] == "ok"
    return loop, rec


def _wrap(e):
    """Angles into [-pi, pi) by the complex exponential (an independent formula)."""
    return np.angle(np.exp(1j * e))


def test_pose_error_wraps_the_angles_only():
    rng = np.random.default_rng(3)
    for npos, p in ((2, 3), (3, 6)):
        target = rng.uniform(-10.0, 10.0, p)
        Y = rng.uniform(-10.0, 10.0, p)
        out = np.empty(p)
        _core.pose_error(target, Y, npos, out)
        e = target - Y
        np.testing.assert_array_equal(out[:npos], e[:npos])  # positions: one subtraction, exact
        assert np.max(np.abs(out[npos:] - _wrap(e[npos:]))) <= REL * 10.0
        assert np.all((out[npos:] >= -np.pi) & (out[npos:] < np.pi))


def test_tracking_acceleration_is_the_pd_law_on_the_reference():
    rng = np.random.default_rng(4)
    target, Y, dY_ref, dY, ddY_ref = rng.normal(size=(5, 6))
    Kp, Kd = 1600.0, 80.0
    err, a = np.empty(6), np.empty(6)
    _core.tracking_acceleration(target, Y, dY_ref, dY, ddY_ref, Kp, Kd, 3, err, a)
    e = target - Y
    e[3:] = _wrap(e[3:])
    expected = ddY_ref + Kd * (dY_ref - dY) + Kp * e
    assert np.max(np.abs(a - expected)) <= REL * np.max(np.abs(expected))


@pytest.mark.parametrize("force_loop", [True, False])
def test_follower_correction_is_a_clipped_pi(force_loop):
    """Three periods of the PI against a numpy replay; the integral limit binds on one component."""
    rng = np.random.default_rng(6)
    T, kp, ki, limit = 1e-3, 0.5, 30.0, 0.02
    integral = np.array([0.0, -0.019, -0.005])
    expected_integral = integral.copy()
    corr = np.empty(3)
    for _ in range(3):
        F_cmd = rng.normal(0.0, 20.0, 3)
        F_seen = F_cmd + np.array([0.1, 5.0, -2.0])  # component 1 winds up past the limit
        _core.follower_correction(F_cmd, F_seen, integral, T, kp, ki, limit, force_loop, corr)
        if force_loop:
            e = F_cmd - F_seen
            expected_integral = np.clip(expected_integral + e * T, -limit, limit)
            expected = F_cmd + kp * e + ki * expected_integral
        else:
            expected = F_cmd
        assert np.max(np.abs(corr - expected)) <= REL * np.max(np.abs(expected))
        assert np.max(np.abs(integral - expected_integral)) <= REL
    if force_loop:
        assert integral[1] == -limit  # the clip bound (F_seen above F_cmd: a negative error)
    else:
        np.testing.assert_array_equal(integral, [0.0, -0.019, -0.005])  # untouched with the loop open


def test_posture_torque_is_the_scaled_pd_toward_rest():
    rng = np.random.default_rng(8)
    n = 7
    A = rng.normal(size=(n, n))
    H = A @ A.T + n * np.eye(n)
    q, dq, q_rest = rng.normal(size=(3, n))
    out = np.empty(n)
    _core.posture_torque(H, q, dq, q_rest, n, 16.0, 8.0, out)
    expected = np.trace(H) / n * (16.0 * (q_rest - q) - 8.0 * dq)
    assert np.max(np.abs(out - expected)) <= REL * np.max(np.abs(expected))


def test_leader_torque_gives_the_commanded_node_acceleration(planar):
    """The plant's own dynamics are the reference: the leader's torque (the follower's held at zero)
    gives the leader's node the acceleration ``LeaderController.acceleration`` commands (1e-9 relative:
    a 3x3 solve and the plant's node equations, conditioned below 1e4)."""
    loop, rec = planar
    plant, leader = loop.plant, loop.leader
    k = 10
    x = rec["x"][k]
    terms = plant.control_terms(x)
    rng = np.random.default_rng(9)
    Y_ref = terms.Y[leader.index + 1] + rng.normal(0.0, 1e-3, 3)
    dY_ref, ddY_ref = rng.normal(0.0, 0.1, (2, 3))
    a_cmd = leader.acceleration(terms, Y_ref, dY_ref, ddY_ref)
    tau = np.zeros(plant.input_size)
    tau[plant.q_slice(leader.index)] = leader.torque(terms, Y_ref, dY_ref, ddY_ref)
    nz = plant.nz
    i, n = leader.index, plant.arms[leader.index].dof
    ddq = plant.rhs(0.0, x, tau)[nz:][plant.q_slice(i)]
    a = terms.J[i, :, :n] @ ddq + terms.Jdq[i]
    assert np.linalg.norm(a - a_cmd) <= 1e-9 * np.linalg.norm(a_cmd)


def _nominal(loop, k):
    """The nominal object motion and node motion of tick ``k``, as the loop samples them."""
    Y0, dY0, ddY0 = (v[0] for v in loop.trajectory.sample(np.array([k * loop.T])))
    return Y0, nominal_node_motion(Y0, dY0, ddY0, loop.grasps, loop.space)


def test_leader_torque_is_what_the_loop_applied(planar):
    """Nothing edited: ``LeaderController.torque`` on the state, split and nominal motion of a recorded tick
    gives the leader's recorded torques bit for bit (the same compiled law on the same numbers)."""
    loop, rec = planar
    plant, leader = loop.plant, loop.leader
    k = 25
    tau_rec = rec["tau"][k][plant.q_slice(leader.index)]
    assert np.all(np.abs(tau_rec) < loop.tau_max[plant.q_slice(leader.index)])  # no saturation at this tick
    terms = plant.control_terms(rec["x"][k])
    Y0, (Yn, dYn, ddYn) = _nominal(loop, k)
    kl = leader.index + 1
    Y_ref = loop.compliance.deformation(leader.index, rec["F_commanded"][k, leader.index], Y0, Yn[kl])
    tau = leader.torque(terms, Y_ref, dYn[kl], ddYn[kl])
    np.testing.assert_array_equal(tau, tau_rec)


def test_follower_torque_is_what_the_loop_applied(planar):
    """The follower at the first tick (its force-error integral starts at zero): bit for bit."""
    loop, rec = planar
    plant = loop.plant
    (i, follower), = loop.followers.items()
    follower.reset()
    k = 0
    terms = plant.control_terms(rec["x"][k])
    Y0, (Yn, dYn, ddYn) = _nominal(loop, k)
    tau = follower.torque(terms, rec["F_commanded"][k, i], rec["F_measured"][k, i], Yn[i + 1], dYn[i + 1],
                          ddYn[i + 1], Y0, loop.T)
    np.testing.assert_array_equal(tau, rec["tau"][k][plant.q_slice(i)])
    assert np.any(follower.integral != 0.0)  # the PI integrated this tick's error


def test_bad_shapes_are_refused_with_the_argument_name(planar):
    loop, rec = planar
    terms = loop.plant.control_terms(rec["x"][0])
    with pytest.raises(ValueError, match="Y_ref"):
        loop.leader.torque(terms, np.zeros(2), np.zeros(3), np.zeros(3))
