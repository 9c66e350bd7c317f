"""coopctrl.mujoco.closed_loop, stepper and comparison: the shipped scenes run on MuJoCo with the same controller."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from coopctrl.mujoco.comparison import compare_plants  # noqa: E402
from coopctrl.scenario import load_scenario  # noqa: E402
from coopctrl.simulator import simulate  # noqa: E402

SCENES = ("two_panda_carry", "ur5e_panda_carry", "three_iiwa_tray", "spatial_two_puma_carry", "planar_two_arm_lift")
#: A short run: the start (the squeeze and the load taken up) and the first part of the motion. The full-length
#: figures come from benchmarks/mujoco_plants.py (docs/data/mujoco_plants.md).
DURATION = 0.3  # [s]
#: The issue's bound on the object's position error RMS: 2x the elastic plant's or 1 mm, whichever is larger.
FLOOR_M = 1e-3


@pytest.mark.parametrize("name", SCENES)
def test_scene_runs_on_mujoco_as_on_the_elastic_plant(name):
    sc = load_scenario(name, {"simulation.duration": DURATION})
    elastic = simulate(sc, node_poses=False).summary()
    result = simulate(sc, node_poses=False, plant="mujoco")
    s = result.summary()
    assert s["status"] == "ok", s["reason"]
    assert s["qp_failures"] == 0
    assert s["integrator"].startswith("mujoco plant")  # the plant named in the summary (and the result folder)
    assert s["object_position_error_rms_m"] <= max(2.0 * elastic["object_position_error_rms_m"], FLOOR_M)
    assert np.isfinite(s["follower_force_error_rms_N"])
    assert len(result.t) == len(simulate(sc, node_poses=False).t)  # every tick of the run recorded


def test_compare_plants_starts_equal_and_names_the_largest_difference():
    """Both runs start from the same state: every difference is zero at t = 0, and the largest is reported at a
    time inside the run."""
    sc = load_scenario("planar_two_arm_lift", {"simulation.duration": 0.2})
    comparison = compare_plants(sc)
    assert comparison.elastic["status"] == comparison.mujoco["status"] == "ok"
    names = [d.signal for d in comparison.differences]
    assert names == ["object position", "object orientation", "contact force", "contact couple", "joint torques"]
    for d in comparison.differences:
        assert 0.0 <= d.time_s <= 0.2 and np.isfinite(d.max_abs) and d.rms <= d.max_abs
    position = comparison.differences[0]
    assert position.max_abs < 1e-4  # [m]: integration error only (docs/mujoco.md); a model error shows in mm
    lines = comparison.lines()
    assert any(line.startswith("object position [m]") for line in lines)


def test_unknown_plant_is_refused():
    sc = load_scenario("planar_two_arm_lift")
    with pytest.raises(ValueError, match="plant = 'bullet' is invalid: expected one of elastic, mujoco"):
        simulate(sc, plant="bullet")


def test_the_plants_differ_by_mujocos_first_order_step_only(monkeypatch):
    """The difference between the plants is MuJoCo's integration error: the elastic plant's RK4 at 1 ms is
    converged (4 substeps move it by < 1e-9 m), and MuJoCo's semi-implicit Euler is first order, so a step 4x
    shorter makes the object's largest position difference 4x smaller. A modelling difference (a mass, an
    inertia, a grasp law) would not shrink with the step."""
    import coopctrl.mujoco.mjcf as mjcf
    from coopctrl.mujoco.comparison import differences

    sc = load_scenario("planar_two_arm_lift", {"simulation.duration": 0.5})
    elastic = simulate(sc, node_poses=False)
    largest = []
    for steps in (2, 8):
        monkeypatch.setattr(mjcf, "MIN_STEPS_PER_PERIOD", steps)
        monkeypatch.setattr(mjcf, "MAX_TIMESTEP", 1.0)
        largest.append(differences(elastic, simulate(sc, node_poses=False, plant="mujoco"))[0].max_abs)
    assert 3.0 < largest[0] / largest[1] < 5.0, largest  # measured 4.0 on the 1 s lift


def test_scene_leaving_the_world_chart_is_refused():
    """two_panda_flip pitches its box past 90 deg in world charts: the loop would re-centre its chart, which the
    MuJoCo plant cannot follow. The shipped carries stay level and run (above)."""
    sc = load_scenario("two_panda_flip")
    assert sc.scene.rotations == "charts"
    with pytest.raises(ValueError, match=r"trajectory.via = 'a pitch of .* is invalid: expected a path within 0.795 rad"):
        simulate(sc, plant="mujoco")


def test_a_turned_state_stops_the_stepper():
    """After its start, the stepper takes only the state it returned: another one (the loop's chart re-centred)
    raises StateChanged, a PlantError the loop reports as the run's stop."""
    from coopctrl.mujoco.stepper import MujocoStepper, StateChanged
    from coopctrl.scenario.build import initial_state

    sc = load_scenario("planar_two_arm_lift")
    stepper = MujocoStepper(sc)
    stepper.reset()
    x0 = initial_state(sc)
    tau = np.zeros(6)
    x1 = stepper.step(None, 0.0, x0, tau, sc.simulation.control_period)
    stepper.step(None, 0.001, x1, tau, sc.simulation.control_period)  # its own state: goes on
    with pytest.raises(StateChanged, match="t = 0.002 s"):
        stepper.step(None, 0.002, x1, tau, sc.simulation.control_period)
    stepper.reset()
    with pytest.raises(StateChanged):
        stepper.step(None, 0.003, x1, tau, sc.simulation.control_period)


def test_continuing_a_run_on_mujoco_is_refused():
    """A continuation carries the loop's state, not MuJoCo's: refused with the reason."""
    sc = load_scenario("planar_two_arm_lift", {"simulation.duration": 0.01})
    state = simulate(sc, node_poses=False).final_state
    with pytest.raises(ValueError, match="continuing a run is for the elastic plant"):
        simulate(sc, plant="mujoco", state=state)
