"""coopctrl/core/tick.h (coopctrl._core.Tick): the closed loop's tick in the compiled core gives the records of the
numba tick it replaced, bit for bit, on every configuration a run can take: sensor noise and quantization, the
elastic split, the reference path (a QP backend in Python between the tick's phases), the grip, friction and torque
rows, a QP that fails, the implicit schemes, a passive run's energy, the energy guard, the tuning probes, the object
impedance law, and a run continued from another's final state.

The numba tick's records of these cases are test data (``tests/golden/tick/*.npz``, written by
``python tests/test_core_tick.py`` while the numba tick ran the loop, 2026-12-06); each case runs again here on the
core and every recorded array must agree with them as the shipped scenes' records do (``tests/test_golden_records.py``:
to 1e-10 of each signal's largest value; bit-identical on this machine)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import coopctrl
import coopctrl.loop.run as loop_run
from coopctrl.controllers.leader_law import object_impedance
from coopctrl.scenario import build
from coopctrl.wiring import closed_loop

FOLDER = Path(__file__).resolve().parent / "golden" / "tick"

#: name -> (scene, overrides, duration [s]): a short run of each configuration.
CASES = {
    "lift_noise": ("planar_two_arm_lift", {
        "sensors.joints.noise_std": 1e-4, "sensors.joints.quantization": 2e-5, "sensors.object.noise_std": 1e-4,
        "sensors.object.quantization": 1e-5, "sensors.forces.noise_std": 0.5, "sensors.forces.quantization": 0.01}, 0.5),
    "lift_elastic_split": ("planar_two_arm_lift", {"load_distribution.split": "elastic"}, 0.5),
    "lift_reference_path": ("planar_two_arm_lift", {"load_distribution.solver": "proxsuite"}, 0.5),
    "lift_grip_friction_torque_rows": ("planar_two_arm_lift", {
        "load_distribution.min_grip": 1.0, "load_distribution.friction_coefficient": 0.8,
        "load_distribution.torque_limits": True}, 0.5),
    "lift_qp_failed": ("planar_two_arm_lift", {
        "load_distribution.min_grip": 1e4, "load_distribution.torque_limits": True,
        "load_distribution.max_consecutive_failures": 3, "simulation.start": "unloaded"}, 0.5),
    "lift_implicit_euler": ("planar_two_arm_lift", {"simulation.integrator": "implicit_euler"}, 0.5),
    "lift_passive": ("planar_two_arm_lift", {"controllers.enabled": False}, 0.3),
    "carry_noise": ("spatial_two_puma_carry", {
        "sensors.joints.noise_std": 1e-4, "sensors.object.noise_std": 1e-4, "sensors.forces.noise_std": 0.5}, 0.4),
    "carry_elastic_split_friction": ("spatial_two_puma_carry", {
        "load_distribution.split": "elastic", "load_distribution.min_grip": 1.0,
        "load_distribution.friction_coefficient": 0.8}, 0.4),
    "carry_reference_path": ("spatial_two_puma_carry", {"load_distribution.solver": "proxsuite"}, 0.3),
    "carry_passive": ("spatial_two_puma_carry", {"controllers.enabled": False}, 0.3),
    "carry_energy_guard": ("spatial_two_puma_carry", {"simulation.max_energy": 1e-3}, 0.3),
    "carry_trbdf2_torque_rows": ("spatial_two_puma_carry", {
        "simulation.integrator": "trbdf2", "load_distribution.torque_limits": True}, 0.3),
}

#: The API cases (laws and probes are given in Python, not in a scene): name -> (scene, duration [s]).
API_CASES = {"lift_object_impedance": ("planar_two_arm_lift", 0.4), "lift_probes": ("planar_two_arm_lift", 0.3),
             "lift_continued": ("planar_two_arm_lift", 0.2)}

#: The record entries compared besides its arrays.
SCALARS = ("status", "reason", "rhs_evaluations", "saturated_ticks")


def _loop_of(name: str):
    if name in CASES:
        scene, overrides, duration = CASES[name]
        scenario = coopctrl.load_scenario(scene, overrides)
        return scenario, closed_loop(scenario), duration
    scene, duration = API_CASES[name]
    scenario = coopctrl.load_scenario(scene)
    if name == "lift_object_impedance":
        return scenario, closed_loop(scenario, leader_law=object_impedance(2.0, 40.0, 400.0, 0.05, 1.0, 10.0)), duration
    if name == "lift_probes":
        from coopctrl.tuning.loop_probes import probed_closed_loop

        loop, leader, followers = probed_closed_loop(scenario)
        leader.offset = np.array([0.002, -0.001, 0.01])
        for probe in followers.values():
            probe.setpoint_offset = np.array([1.0, -2.0, 0.1])
            probe.error_gain = np.array([0.5, 1.0, 2.0])
            probe.measurement_delay = np.array([2, 0, 1])
        return scenario, loop, duration
    return scenario, closed_loop(scenario), duration


def _run(loop, scenario, duration_s: float, start=None) -> dict:
    N = int(round(duration_s / loop.T)) + 1
    x0 = build.initial_state(scenario, loop) if start is None else None
    return loop_run.run_compiled(loop, loop.empty_record(N), x0, N, start=start)


def run_case(name: str) -> dict:
    """The record of the case ``name``: its arrays (but the QP's solve times) and :data:`SCALARS`."""
    scenario, loop, duration = _loop_of(name)
    rec = _run(loop, scenario, duration)
    if name == "lift_continued":  # the second half, continued from the first's final state
        rec = _run(closed_loop(scenario), scenario, duration, start=rec["final_state"])
    out = {key: np.asarray(value) for key, value in rec.items()
           if isinstance(value, np.ndarray) and key != "qp_solve_time_s"}
    for key in SCALARS:
        out[key] = np.array(-1 if rec[key] is None else rec[key])
    out["qp_status_names"] = np.array(rec["qp_status"])
    return out


def _assert_recorded(got, want, key) -> None:
    """Integers and names exactly; reals to 1e-10 of the signal's largest magnitude, NaN where the record has NaN
    (the golden records' rule, tests/test_golden_records.py: bit-identical on this machine, and room for a compiler
    that rounds differently)."""
    if want.dtype.kind != "f":
        np.testing.assert_array_equal(got, want, err_msg=key)
        return
    assert got.shape == want.shape, key
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want), err_msg=key)
    finite = np.isfinite(want)
    scale = float(np.abs(want[finite]).max()) if finite.any() else 0.0
    np.testing.assert_allclose(got[finite], want[finite], rtol=0, atol=1e-10 * scale, err_msg=key)


@pytest.mark.parametrize("name", list(CASES) + list(API_CASES))
def test_the_core_tick_records_what_the_numba_tick_recorded(name):
    got = run_case(name)
    with np.load(FOLDER / f"{name}.npz") as want:
        assert sorted(got) == sorted(want.files)
        for key in want.files:
            _assert_recorded(got[key], want[key], key)
    if name == "lift_qp_failed":  # the case reaches the failure policy: its min_grip is beyond the torque limits
        assert str(got["status"]) == "qp_failed"
    if name == "carry_energy_guard":
        assert str(got["status"]) != "ok"
    if name.endswith("passive"):
        assert np.all(np.isfinite(got["energy"]))


def test_a_leader_law_written_in_python_runs_on_the_core():
    """A plain Python function as the leader's law (the documented slower path) gives the torques of the built-in
    law it restates."""
    scenario = coopctrl.load_scenario("planar_two_arm_lift")
    loop = closed_loop(scenario)
    Kp, Kd = loop.leader.Kp, loop.leader.Kd

    def restated(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
        for a in range(a_cmd.shape[0]):
            a_cmd[a] = ddY_ref[a] + params[1] * (dY_ref[a] - dY[a]) + params[0] * err[a]

    from coopctrl.controllers.leader_law import LeaderLaw, computed_torque

    built_in = _run(closed_loop(scenario, leader_law=computed_torque(Kp, Kd)), scenario, 0.2)
    python = _run(closed_loop(scenario, leader_law=LeaderLaw(restated, (Kp, Kd))), scenario, 0.2)
    assert python["status"] == built_in["status"] == "ok"
    np.testing.assert_allclose(python["tau"], built_in["tau"], rtol=0, atol=1e-9 * np.abs(built_in["tau"]).max())


def write(names) -> None:
    FOLDER.mkdir(parents=True, exist_ok=True)
    for name in names:
        record = run_case(name)
        np.savez_compressed(FOLDER / f"{name}.npz", **record)
        print(f"{name}: {record['status']}, {len(record['t'])} ticks")


if __name__ == "__main__":
    write(sys.argv[1:] or list(CASES) + list(API_CASES))


def test_the_follower_law_hook_takes_the_followers_node_acceleration():
    """A follower law that restates the followers' computed torque gives their torques (to rounding: the same
    formula in another order); a stiffer one changes the followers' torques and leaves the run's start alone."""
    scenario = coopctrl.load_scenario("planar_two_arm_lift")
    loop = closed_loop(scenario)
    follower = next(iter(loop.followers.values()))
    Kp, Kd = follower.Kp, follower.Kd

    def restated(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
        for a in range(a_cmd.shape[0]):
            a_cmd[a] = ddY_ref[a] + params[1] * (dY_ref[a] - dY[a]) + params[0] * err[a]

    from coopctrl.controllers.leader_law import LeaderLaw

    own = _run(loop, scenario, 0.2)
    same = _run(closed_loop(scenario, follower_law=LeaderLaw(restated, (Kp, Kd))), scenario, 0.2)
    stiffer = _run(closed_loop(scenario, follower_law=LeaderLaw(restated, (4.0 * Kp, 2.0 * Kd))), scenario, 0.2)
    assert own["status"] == same["status"] == stiffer["status"] == "ok"
    scale = np.abs(own["tau"]).max()
    np.testing.assert_allclose(same["tau"], own["tau"], rtol=0, atol=1e-9 * scale)
    followers = [loop.plant.q_slice(i) for i in loop.followers]
    moved = max(np.abs(stiffer["tau"][:, s] - own["tau"][:, s]).max() for s in followers)
    assert moved > 1e-6 * scale


def test_a_law_that_raises_stops_the_run_with_its_exception():
    scenario = coopctrl.load_scenario("planar_two_arm_lift")

    def broken(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
        raise ZeroDivisionError("the law's own error")

    from coopctrl.controllers.leader_law import LeaderLaw

    with pytest.raises(ZeroDivisionError, match="the law's own error"):
        _run(closed_loop(scenario, leader_law=LeaderLaw(broken, (1.0,))), scenario, 0.05)

    def silent(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
        pass  # writes nothing: a_cmd stays NaN

    with pytest.raises(ValueError, match=r"a_cmd\[0\]"):
        _run(closed_loop(scenario, follower_law=LeaderLaw(silent, (1.0,))), scenario, 0.05)

