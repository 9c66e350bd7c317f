"""Tests of ``trajectory.orientation`` (coopctrl.scenario.trajectory) and the trajectory the builder makes of it."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.errors import ScenarioError
from coopctrl.scenario import build, load_scenario
from coopctrl.trajectory import GeodesicTrajectory, MinimumJerkTrajectory


def test_the_default_turns_on_the_rotation_in_charts_and_on_the_books_angles_in_them():
    """Absent ``trajectory.orientation`` follows the scene's rotations (issue 20: charts are the default)."""
    scenario = load_scenario("three_iiwa_tray")
    assert scenario.scene.rotations == "charts" and scenario.trajectory.orientation == "geodesic"
    assert isinstance(build.trajectory(scenario), GeodesicTrajectory)
    scenario = load_scenario("three_iiwa_tray", {"scene.rotations": "book"})
    assert scenario.trajectory.orientation == "euler"
    assert type(build.trajectory(scenario)) is MinimumJerkTrajectory


def test_geodesic_selects_the_rotation_group_path():
    # the tray turns about world z only (yaw 0 -> 0.3 rad): the geodesic's Euler view is the book's path
    euler = build.trajectory(load_scenario("three_iiwa_tray", {"trajectory.orientation": "euler"}))
    path = build.trajectory(load_scenario("three_iiwa_tray", {"trajectory.orientation": "geodesic"}))
    assert isinstance(path, GeodesicTrajectory)
    t = np.linspace(0.0, euler.duration, 41)
    for ours, book in zip(path.sample(t), euler.sample(t)):
        np.testing.assert_allclose(ours, book, rtol=0, atol=1e-13)  # rounding of the quaternion round trip


def test_a_planar_scene_keeps_its_one_angle_trajectory():
    scenario = load_scenario("planar_two_arm_lift", {"trajectory.orientation": "geodesic"})
    assert type(build.trajectory(scenario)) is MinimumJerkTrajectory


def test_a_geodesic_path_into_the_euler_band_is_bad_input_naming_the_via():
    # from pitch 75 deg to 2.0 rad (115 deg): the geodesic passes pitch 90 deg, where the loop has no coordinates
    scenario = load_scenario("euler_singularity", {"trajectory.orientation": "geodesic", "scene.rotations": "book",
                                                   "trajectory.via[1].pose": [0.0, 0.0, 0.6, 0.0, 2.0, 0.0]})
    with pytest.raises(ScenarioError, match=r"trajectory\.via\[1\]\.pose = \[.*\] is invalid: expected a geodesic "
                                            r"path .* reaches pitch 85\.\d\d deg at t = ") as info:
        build.trajectory(scenario)
    assert "\n" not in str(info.value)


def test_an_unknown_orientation_is_refused():
    with pytest.raises(ScenarioError, match=r"orientation = 'slerp' is invalid: expected .*'geodesic'"):
        load_scenario("three_iiwa_tray", {"trajectory.orientation": "slerp"})
