"""Closed-loop acceptance tests (issue 2/5): tracking, force regulation, QP limits, divergence.

Each runs a shipped scenario for its full duration (a few seconds of simulated time).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import coopctrl

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"


def run(name, **overrides):
    return coopctrl.simulate(coopctrl.load_scenario(SCENARIOS / f"{name}.toml", overrides or None))


def follower_force_scale(r):
    """Mean magnitude [N] of the followers' commanded contact force (the 'nominal force')."""
    npos = 3 if r.space == "spatial" else 2
    return float(np.mean(np.linalg.norm(r.F_commanded[:, r.followers, :npos], axis=-1)))


@pytest.fixture(scope="module", params=["planar_two_arm_lift", "spatial_two_puma_carry"])
def carry(request):
    return run(request.param)


def test_carry_moves_object_03m_and_03rad(carry):
    """The task itself: the nominal path spans 0.3 m and 0.3 rad."""
    npos = 3 if carry.space == "spatial" else 2
    Yn = carry.Y0_nominal
    assert np.linalg.norm(Yn[-1, :npos] - Yn[0, :npos]) == pytest.approx(0.3, abs=1e-6)
    assert np.max(np.abs(Yn[-1, npos:] - Yn[0, npos:])) == pytest.approx(0.3, abs=1e-9)


def test_carry_tracking(carry):
    s = carry.summary()
    assert s["status"] == "ok", s["reason"]
    assert s["object_position_error_rms_m"] <= 2e-3
    assert s["object_position_error_max_m"] <= 5e-3
    assert s["qp_failures"] == 0


def test_carry_follower_force_error(carry):
    s = carry.summary()
    assert s["follower_force_error_rms_N"] <= 0.05 * follower_force_scale(carry)


def test_carry_squeeze_held_within_10_percent(carry):
    dev = np.abs(carry.squeeze - carry.squeeze_desired)
    assert np.all(carry.squeeze_desired > 0)
    assert np.max(dev / carry.squeeze_desired) <= 0.10


def test_three_arm_carry_torque_limits_active_and_respected():
    r = run("spatial_three_arm_carry")
    s = r.summary()
    assert s["status"] == "ok", s["reason"]
    assert s["qp_active_constraints"].get("torque_limits", 0) > 0, "the torque limits never became active"
    assert s["max_torque_ratio"] <= 1.0
    assert s["torque_saturated_ticks"] == 0
    assert s["qp_failures"] == 0
    # the task is completed: the object ends on its final pose
    end_error = np.linalg.norm(r.Y0[-1, :3] - r.Y0_nominal[-1, :3])
    assert end_error <= 5e-3
    assert s["object_position_error_max_m"] <= 5e-3


def test_force_regulation_matters():
    """With a 2 mm grasp error that the controllers do not know, position control alone leaves a
    squeeze error >= 5 times the one with the followers' force loop on."""
    err = {"arms[1].grasp_error": [0.002, 0.001, 0.0]}
    on = run("planar_two_arm_lift", **err).summary()
    off = run("planar_two_arm_lift", **err, **{"controllers.followers.force_loop": False}).summary()
    assert on["status"] == off["status"] == "ok"
    assert off["internal_force_error_rms_N"] >= 5.0 * on["internal_force_error_rms_N"]


def test_heavy_payload_limits_bind_in_the_plane():
    s = run("heavy_payload_torque_limits").summary()
    assert s["status"] == "ok", s["reason"]
    assert s["qp_active_constraints"].get("torque_limits", 0) > 0
    assert s["max_torque_ratio"] <= 1.0


def test_infeasible_load_stops_with_qp_failed():
    """A payload no split can carry within the torque limits ends the run as 'qp_failed'."""
    r = run("heavy_payload_torque_limits", **{"object.mass": 60.0, "simulation.duration": 0.05})
    assert r.status == "qp_failed"
    assert "torque_limits" in r.reason


def test_divergence_is_detected_and_explained():
    """Explicit Euler on an undamped-enough stiff grasp at a coarse step: stopped, not NaN."""
    r = run("stiff_grasp_extreme", **{"simulation.integrator": "euler", "simulation.control_period": 0.002})
    assert r.status == "diverged"
    assert "diverged at t =" in r.reason and "try a step of at most" in r.reason
    assert np.all(np.isfinite(r.x)), "recorded states must be the finite ones before the stop"


def test_buckling_scene_says_why():
    r = run("central_spring_buckling")
    assert r.status == "diverged"
    assert "negative eigenvalue" in r.reason and "buckles" in r.reason


def test_gripping_builds_up_squeeze_from_zero():
    r = run("gripping_immobile_object")
    assert r.model["unloaded_state"] == "immobile"
    assert abs(r.squeeze[0, 0]) < 1.0  # starts unloaded
    assert r.squeeze[-1, 0] == pytest.approx(r.squeeze_desired[0], rel=0.02)


def test_sensor_noise_is_seeded():
    noisy = {"sensors.forces.noise_std": 0.2, "sensors.joints.noise_std": 1e-5, "simulation.duration": 0.2}
    a = run("planar_two_arm_lift", **noisy)
    b = run("planar_two_arm_lift", **noisy)
    c = run("planar_two_arm_lift", **noisy, **{"simulation.seed": 1})
    np.testing.assert_array_equal(a.x, b.x)
    assert not np.array_equal(a.x, c.x)
    assert a.status == "ok"


def test_passive_run_reports_energy_drift():
    """Without control and damping the summary reports the energy drift; RK4 at h = 0.5 ms keeps
    it small (h * omega_max ~ 0.3 here: RK4's error per period ~ (h omega)^4 / 120)."""
    undamped = {f"springs[{i}].{k}": 0.0 for i in (0, 1) for k in ("damping", "torsion_damping")}
    passive = {"controllers.enabled": False, "simulation.duration": 1.0, "simulation.control_period": 5e-4}
    s = run("planar_two_arm_lift", **passive, **undamped).summary()
    assert s["status"] == "ok"
    assert s["energy_drift_rel"] is not None and s["energy_drift_rel"] <= 1e-5
    assert s["qp_solves"] == 0
    damped = run("planar_two_arm_lift", **passive).summary()
    assert damped["energy_drift_rel"] is None
