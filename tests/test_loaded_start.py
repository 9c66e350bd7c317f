"""The loaded start (coopctrl/loop/loaded_start.py): planned from the loop's parts, the same state the
loop plans, with the object on its nominal pose and the grasps carrying the QP split of t = 0."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.controllers import GraspCompliance
from coopctrl.load_distribution import LoadDistribution
from coopctrl.loop.loaded_start import loaded_state
from coopctrl.loop.qp_inputs import contact_normals, qp_torque_limits, torque_model
from coopctrl.scenario import build, load_scenario
from coopctrl.simulator import closed_loop
from test_cli import REPO

SCENES = ["spatial_two_puma_carry", "planar_two_arm_lift", "heavy_payload_torque_limits"]


def load(name, **overrides):
    path = REPO / "scenarios" / f"{name}.toml"
    if not path.exists():
        pytest.skip(f"no scenario {name}")
    return load_scenario(path, overrides)


@pytest.mark.parametrize("name", SCENES)
def test_the_scenario_and_the_loop_plan_the_same_loaded_start(name):
    """``build.initial_state`` (scenario layer, no loop) and ``ClosedLoop.loaded_state`` run the same
    function on the same parts: bit-identical states."""
    scenario = load(name)
    x_unloaded = build.unloaded_state(scenario)
    assert np.array_equal(build.initial_state(scenario), closed_loop(scenario).loaded_state(x_unloaded))


@pytest.mark.parametrize("name", SCENES)
def test_the_loaded_start_is_at_rest_on_the_nominal_pose_carrying_the_split(name):
    scenario = load(name)
    plant = build.build_plant(scenario)
    path = build.trajectory(scenario)
    grasps = build.nominal_grasps(scenario)
    ld = scenario.load_distribution
    x0 = build.unloaded_state(scenario)
    x = loaded_state(plant, path, grasps, ld, GraspCompliance(plant), ld.torque_limits, x0)
    nz, p = plant.nz, plant.p
    assert np.array_equal(x[nz - p:nz], path.evaluate(0.0)[0])  # the object on its nominal pose
    assert not np.any(x[nz:])  # at rest
    # the interconnections carry the planned split: the contact wrenches of the loaded state against the
    # QP's answer at the same (nominal) contact positions
    terms = plant.control_terms(x)
    loop = closed_loop(scenario)
    from coopctrl.controllers import required_object_wrench
    from plants.cooperative import nominal_node_motion

    Y0, dY0, ddY0 = path.evaluate(0.0)
    Yn = nominal_node_motion(Y0, dY0, ddY0, grasps, scenario.space)[0]
    w = required_object_wrench(scenario.space, loop.object_mass, loop.object_inertia, loop.gravity, Y0, dY0, ddY0)
    kwargs = {}
    if ld.min_grip is not None or ld.friction_coefficient is not None:
        kwargs["normals"] = contact_normals(plant, plant.control_terms(x0))
    if ld.torque_limits:
        kwargs["jacobians"], kwargs["biases"] = torque_model(plant, plant.control_terms(x0), np.zeros((plant.arm_count + 1, p)))
        kwargs["tau_max"] = qp_torque_limits(plant)
    F = LoadDistribution(ld, scenario.space, plant.arm_count).solve(Yn[1:, :loop.npos], Y0[:loop.npos], w, **kwargs).F
    # the inverse kinematics places each node to ~1e-9 m; through grasp stiffnesses of ~1e5 N/m and the
    # compliance map's linearization, the carried wrench agrees with the plan to well under 1 % of the load
    scale = max(1.0, float(np.max(np.abs(F))))
    assert np.max(np.abs(np.asarray(terms.Fw) - F)) < 1e-2 * scale
