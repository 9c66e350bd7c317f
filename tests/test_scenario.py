"""Tests of coopctrl.scenario: defaults, TOML round trip, every kind of bad input, overrides."""

from __future__ import annotations

import copy
import math
import sys
import tomllib

import pytest

from coopctrl.errors import ScenarioError
from coopctrl.io import dumps_toml
from coopctrl.scenario import (
    ArmConfig,
    Scenario,
    SimulationConfig,
    SpringConfig,
    load_scenario,
    parse_override_value,
    scenario_from_dict,
)


def write(tmp_path, data, name="scene.toml"):
    path = tmp_path / name
    path.write_text(dumps_toml(data) if isinstance(data, dict) else data, encoding="utf-8")
    return path


def base() -> dict:
    return Scenario().to_dict()


def spatial() -> dict:
    return {
        "name": "spatial_two_puma",
        "description": "Two PUMA 560 arms lift a box.",
        "scene": {"space": "spatial"},
        "object": {"mass": 2.0, "inertia": [0.02, 0.02, 0.03], "pose": [0.0, 0.0, 0.6, 0.0, 0.0, 0.0]},
        "arms": [
            {"model": "puma560", "role": "leader", "base": [-0.7, 0, 0, 0, 0, 0], "grasp": [-0.1, 0, 0, 0, 0, 0]},
            {"model": "puma560", "role": "follower", "base": [0.7, 0, 0, 0, 0, 0], "grasp": [0.1, 0, 0, math.pi, 0, 0]},
        ],
        "trajectory": {"via": [{"time": 0.0, "pose": [0.0, 0.0, 0.6, 0.0, 0.0, 0.0]},
                               {"time": 1.0, "pose": [0.0, 0.0, 0.7, 0.0, 0.0, 0.0]}]},
    }


def raises(match_path, fn, *args, **kwargs) -> ScenarioError:
    with pytest.raises(ScenarioError) as info:
        fn(*args, **kwargs)
    err = info.value
    message = str(err)
    assert "\n" not in message, message
    assert err.path == match_path, message
    assert match_path in message
    return err


# ---------------------------------------------------------------------- valid scenes
def test_defaults_are_valid_planar_two_arm_scene():
    s = Scenario()
    assert s.space == "planar" and len(s.arms) == 2
    assert s.leader == 0 and s.followers == [1]
    assert [sp.pair for sp in s.springs] == [(0, 1), (0, 2)]
    assert s.trajectory.via[0].pose == s.object.pose
    assert s.trajectory.via[-1].pose[1] == pytest.approx(s.object.pose[1] + 0.1)
    assert s.state_size == 2 * (3 + 3 + 3)
    assert load_scenario(None) == s


def test_empty_file_is_refused_and_says_what_it_lacks(tmp_path):
    # The built-in default scene is `coopctrl run` without a file; an empty file is a mistake.
    err = raises("arms", load_scenario, write(tmp_path, ""))
    assert "the file is empty" in str(err) and "without a file" in str(err)
    assert scenario_from_dict({}) == Scenario()  # the Python API keeps the default scene


def test_spatial_file_without_arms_names_what_it_wrote(tmp_path):
    data = spatial()
    del data["arms"]
    err = raises("arms", load_scenario, write(tmp_path, data))
    # it lists the spatial models, never the planar3r default the user did not write
    assert "'puma560'" in str(err) and "planar3r" not in str(err)
    assert "it sets: name, description, scene, object, trajectory" in str(err)


def test_file_without_trajectory_is_refused(tmp_path):
    data = spatial()
    del data["trajectory"]
    err = raises("trajectory", load_scenario, write(tmp_path, data))
    assert "via" in str(err)


def test_object_pose_comes_from_the_trajectory(tmp_path):
    data = spatial()
    del data["object"]["pose"]
    s = load_scenario(write(tmp_path, data))
    assert s.object.pose == tuple(data["trajectory"]["via"][0]["pose"])
    data["object"]["pose"] = [0.0, 0.0, 0.61, 0.0, 0.0, 0.0]
    err = raises("object.pose", load_scenario, write(tmp_path, data))
    assert "trajectory.via[0].pose = [0.0, 0.0, 0.6" in str(err) and "leave object.pose out" in str(err)


RANGES = [  # issue 11 items 4 and 7: values that hung or crashed before the schema had ranges
    ("springs[0].stiffness", 1.7976931348623157e308, "<= 1e10 [N/m]"),
    ("simulation.duration", 1e300, "<= 10000 [s]"),
    ("simulation.control_period", 1e-300, ">= 1e-6"),
    ("controllers.leader.natural_frequency", 1e300, "<= 100000 [rad/s]"),
    ("object.mass", 1e-300, ">= 0.0001"),
]


@pytest.mark.parametrize("dotted, value, allowed", RANGES, ids=[d for d, _, _ in RANGES])
def test_values_outside_the_schema_ranges_are_refused(tmp_path, dotted, value, allowed):
    err = raises(dotted, load_scenario, write(tmp_path, base()), {dotted: value})
    assert allowed in str(err)


def test_sections_are_frozen():
    s = Scenario()
    with pytest.raises(AttributeError):
        s.simulation.substeps = 3  # type: ignore[misc]


def test_round_trip_through_toml(tmp_path):
    s = load_scenario(write(tmp_path, spatial()))
    text = dumps_toml(s.to_dict())
    again = load_scenario(write(tmp_path, text, "again.toml"))
    assert again == s
    assert again.source.endswith("again.toml")
    assert tomllib.loads(text) == s.to_dict()


def test_round_trip_defaults_dict():
    assert Scenario.from_dict(Scenario().to_dict()) == Scenario()


def test_spatial_scene_and_node_defaults(tmp_path):
    s = load_scenario(write(tmp_path, spatial()))
    assert s.pose_size == 6
    assert s.arms[0].node_inertia == (1e-3,) * 3
    assert s.state_size == 2 * (6 + 6 + 6)
    assert s.trajectory.via[1].pose[2] == pytest.approx(0.7)


def with_springs(data: dict, **keys) -> dict:
    """``data`` with one spring per arm (object to arm node), each with ``keys``."""
    data = copy.deepcopy(data)
    data["springs"] = [{"pair": [0, k], **keys} for k in (1, 2)]
    return data


def test_a_spatial_scene_takes_its_rotations_in_charts_by_default(tmp_path):
    """Issue 20: a spatial scene of the mobile model runs in charts unless it says otherwise; its springs'
    rotational terms are then geodesic and its trajectory turns on the rotation."""
    s = load_scenario(write(tmp_path, spatial()))
    assert s.scene.rotations == "charts" and s.trajectory.orientation == "geodesic"
    assert {sp.rotation_form for sp in s.springs} == {"geodesic"}
    for element in ("offset", "central"):  # both forms of an offset element are chart-free
        for form in ("book", "geodesic"):
            keys = {"element": element, "rotation_form": form}
            if element == "central":
                keys["torsion"] = 0.0 if form == "book" else 10.0  # the book's torsion without torsion: none
            s = load_scenario(write(tmp_path, with_springs(spatial(), **keys)))
            assert s.scene.rotations == "charts" and {sp.rotation_form for sp in s.springs} == {form}


@pytest.mark.parametrize("keys, field", [
    ({"element": "central", "rotation_form": "book", "torsion": 10.0}, "springs[0].rotation_form"),
    ({"element": "central", "stiffness": [2e4, 2e4, 1e4]}, "springs[0].stiffness"),
    ({"damping_form": "book", "torsion_damping": 0.05}, "springs[0].damping_form"),
])
def test_springs_that_need_the_books_angles_keep_them_unless_charts_are_asked_for(tmp_path, keys, field):
    """A spring that depends on the angles' chart keeps the scene in the book's world angles (its forms and the
    Euler trajectory); asking for charts with it is refused, naming the spring's field."""
    data = with_springs(spatial(), **keys)
    s = load_scenario(write(tmp_path, data))
    assert s.scene.rotations == "book" and s.trajectory.orientation == "euler"
    assert all(sp.rotation_form == "book" for sp in s.springs if "rotation_form" not in keys)
    data["scene"]["rotations"] = "charts"
    raises(field, load_scenario, write(tmp_path, data))


def test_the_books_angles_are_kept_where_charts_do_not_apply(tmp_path):
    """A planar scene (one angle), a spatial scene of the immobile model (linear in the world angles) and a
    scene that asks for the book's angles take the book's forms."""
    assert Scenario().scene.rotations == "book" and Scenario().trajectory.orientation == "euler"
    immobile = spatial()
    immobile["scene"]["unloaded_state"] = "immobile"
    book = spatial()
    book["scene"]["rotations"] = "book"
    for data in (immobile, book):
        s = load_scenario(write(tmp_path, data))
        assert s.scene.rotations == "book" and s.trajectory.orientation == "euler"
        assert {sp.rotation_form for sp in s.springs} == {"book"}


def test_a_scene_in_charts_round_trips_through_toml(tmp_path):
    """The chosen rotations, forms and orientation are written out, so the file read back is the same scene."""
    s = load_scenario(write(tmp_path, spatial()))
    again = load_scenario(write(tmp_path, dumps_toml(s.to_dict()), "again.toml"))
    assert again == s and again.scene.rotations == "charts"


def test_three_arms_get_one_spring_each(tmp_path):
    data = base()
    data.pop("springs")
    data["arms"].append({"model": "contact_point", "role": "follower", "base": [0, 0, 0], "grasp": [0, 0.1, -1.57]})
    s = load_scenario(write(tmp_path, data))
    assert [sp.pair for sp in s.springs] == [(0, 1), (0, 2), (0, 3)]
    assert s.load_distribution.squeeze_per_pair(3) == (5.0, 5.0, 5.0)


def test_per_axis_stiffness_and_torsion(tmp_path):
    data = base()
    data["springs"][0]["stiffness"] = [1e4, 2e4]
    data["springs"][0]["torsion"] = 0
    s = load_scenario(write(tmp_path, data))
    assert s.springs[0].stiffness_per_axis("planar") == (1e4, 2e4)
    assert s.springs[0].torsion_per_axis("planar") == (0.0,)


# ---------------------------------------------------------------------- file errors
def test_missing_file(tmp_path):
    err = raises("", load_scenario, tmp_path / "nope.toml")
    assert "nope.toml" in str(err) and "not found" in str(err)


def test_toml_syntax_error_names_line(tmp_path):
    path = write(tmp_path, 'name = "x"\n[simulation]\nduration = = 2\n')
    err = raises("", load_scenario, path)
    assert "line 3" in str(err) and "scene.toml" in str(err)


# ---------------------------------------------------------------------- bad fields
def _set(data, dotted, value):
    node = data
    parts = dotted.split(".")
    for part in parts[:-1]:
        if "[" in part:
            name, index = part[:-1].split("[")
            node = node[name][int(index)]
        else:
            node = node.setdefault(part, {})
    node[parts[-1]] = value
    return data


BAD = [
    ("bogus", 1, "bogus"),
    ("simulation.bogus", 1, "simulation.bogus"),
    ("controllers.leader.bogus", 1, "controllers.leader.bogus"),
    ("arms[1].bogus", 1, "arms[1].bogus"),
    ("trajectory.via[1].bogus", 1, "trajectory.via[1].bogus"),
    ("object.mass", "heavy", "object.mass"),
    ("object.mass", -1.0, "object.mass"),
    ("object.mass", 0.0, "object.mass"),
    ("object.mass", float("nan"), "object.mass"),
    ("object.mass", float("inf"), "object.mass"),
    ("object.mass", True, "object.mass"),
    ("arms[1].node_mass", -0.1, "arms[1].node_mass"),
    ("springs[0].stiffness", -1e4, "springs[0].stiffness"),
    ("springs[0].stiffness", float("nan"), "springs[0].stiffness"),
    ("springs[1].stiffness", "stiff", "springs[1].stiffness"),
    ("springs[0].stiffness", [1e4, 1e4, 1e4], "springs[0].stiffness"),
    ("springs[0].torsion", -1.0, "springs[0].torsion"),
    ("springs[0].damping", float("inf"), "springs[0].damping"),
    ("springs[0].element", "rubber", "springs[0].element"),
    ("springs[1].pair", [0, 3], "springs[1].pair"),
    ("springs[1].pair", [1, 1], "springs[1].pair"),
    ("springs[1].pair", [0, 1], "springs[1].pair"),
    ("simulation.substeps", 0, "simulation.substeps"),
    ("simulation.substeps", 1.5, "simulation.substeps"),
    ("simulation.integrator", "rk89", "simulation.integrator"),  # rk45 is an error-controlled scheme
    ("simulation.duration", "1 s", "simulation.duration"),
    ("simulation.control_period", 0.0, "simulation.control_period"),
    ("scene.space", "3d", "scene.space"),
    ("scene.gravity", -9.81, "scene.gravity"),
    ("object.pose", [0.0, 0.5], "object.pose"),
    ("object.pose", [0.0, 0.0, 0.5, 0.0, 0.0, 0.0], "object.pose"),
    ("object.inertia", [0.01, 0.01, 0.01], "object.inertia"),
    ("arms[1].grasp", [0.1, 0.0], "arms[1].grasp"),
    ("arms[1].grasp", [0.1, 0.0, 0.0, 0.0, 0.0, 0.0], "arms[1].grasp"),
    ("arms[0].base", "origin", "arms[0].base"),
    ("arms[1].role", "leader", "arms[1].role"),
    ("arms[0].model", "puma560", "arms[0].model"),
    ("arms[0].model", "ur5", "arms[0].model"),
    ("arms[0].tau_max", [10.0, 10.0], "arms[0].tau_max"),
    ("arms[0].q0", [0.0, 0.1, "a"], "arms[0].q0"),
    ("trajectory.via[1].time", 0.0, "trajectory.via[1].time"),
    ("trajectory.via[0].pose", [0.0, 0.4, 0.0], "object.pose"),  # both given and different: the check names object.pose
    ("trajectory.via[1].pose", [0.0, 0.4], "trajectory.via[1].pose"),
    ("load_distribution.split", "equal", "load_distribution.split"),
    ("load_distribution.shares", [1.0, 1.0, 1.0], "load_distribution.shares"),
    ("load_distribution.squeeze", -5.0, "load_distribution.squeeze"),
    ("load_distribution.friction_facets", 2, "load_distribution.friction_facets"),
    ("load_distribution.torque_limits", "yes", "load_distribution.torque_limits"),
    ("controllers.followers.force_kp", -1.0, "controllers.followers.force_kp"),
    ("sensors.forces.noise_std", -0.1, "sensors.forces.noise_std"),
    ("simulation", 3, "simulation"),
    ("arms", {"model": "planar3r"}, "arms"),
    ("description", "two\nlines", "description"),
]


@pytest.mark.parametrize("dotted, value, path", BAD, ids=[f"{d}={v!r}" for d, v, _ in BAD])
def test_bad_field_names_its_path(tmp_path, dotted, value, path):
    data = _set(base(), dotted, value)
    err = raises(path, load_scenario, write(tmp_path, data))
    assert "scene.toml" in str(err)
    assert "expected" in str(err)


def test_unknown_key_lists_allowed_keys(tmp_path):
    err = raises("arms[1].grasps", load_scenario, write(tmp_path, _set(base(), "arms[1].grasps", [0, 0, 0])))
    assert "grasp" in err.allowed and "node_mass" in err.allowed


def test_missing_required_arm_key(tmp_path):
    data = base()
    del data["arms"][1]["grasp"]
    raises("arms[1].grasp", load_scenario, write(tmp_path, data))


def test_two_leaders(tmp_path):
    raises("arms[1].role", load_scenario, write(tmp_path, _set(base(), "arms[1].role", "leader")))


def test_no_leader(tmp_path):
    raises("arms", load_scenario, write(tmp_path, _set(base(), "arms[0].role", "follower")))


def test_one_arm_is_not_enough(tmp_path):
    data = base()
    data["arms"] = data["arms"][:1]
    data.pop("springs")
    raises("arms", load_scenario, write(tmp_path, data))


def test_disconnected_springs(tmp_path):
    data = base()
    data["springs"] = data["springs"][:1]
    err = raises("springs", load_scenario, write(tmp_path, data))
    assert "[2]" in str(err)


def test_planar_arm_in_spatial_scene(tmp_path):
    data = spatial()
    data["arms"][1]["model"] = "planar3r"
    raises("arms[1].model", load_scenario, write(tmp_path, data))


def test_euler_singularity_rejected(tmp_path):
    data = spatial()
    data["object"]["pose"] = [0.0, 0.0, 0.6, 0.0, math.pi / 2, 0.0]
    raises("object.pose", load_scenario, write(tmp_path, data))


def test_direct_construction_checks_fields():
    raises("substeps", SimulationConfig, substeps=0)
    raises("pair", SpringConfig, pair=(0, -1))
    raises("grasp", ArmConfig, model="planar3r", role="leader", base=(0, 0, 0), grasp=(0, 0))
    raises("simulation", Scenario, simulation={"substeps": 2})


# ---------------------------------------------------------------------- overrides
def test_override_integrator_and_stiffness(tmp_path):
    s = load_scenario(write(tmp_path, base()), {"simulation.integrator": "euler", "springs[0].stiffness": "1e6"})
    assert s.simulation.integrator == "euler"
    assert s.springs[0].stiffness == 1e6 and isinstance(s.springs[0].stiffness, float)


def test_override_list_value_and_python_value():
    s = load_scenario(None, {"arms[1].grasp": "[0.12, 0, 3.0]", "simulation.substeps": 4, "object.mass": 2})
    assert s.arms[1].grasp == (0.12, 0.0, 3.0)
    assert s.simulation.substeps == 4 and s.object.mass == 2.0


def test_override_into_defaults_without_file():
    s = load_scenario(None, {"springs[1].stiffness": "2e4", "trajectory.via[1].time": "2", "controllers.leader.natural_frequency": "40"})
    assert s.springs[1].stiffness == 2e4
    assert s.trajectory.via[1].time == 2.0
    assert s.controllers.leader.natural_frequency == 40.0


def test_override_does_not_mutate_input():
    data = base()
    before = copy.deepcopy(data)
    scenario_from_dict(data, overrides={"simulation.integrator": "euler"})
    assert data == before


@pytest.mark.parametrize(
    "path, value, named",
    [
        ("simulation.bogus", "1", "simulation.bogus"),
        ("bogus", "1", "bogus"),
        ("bogus.deeper", "1", "bogus.deeper"),
        ("springs[7].stiffness", "1e6", "springs[7].stiffness"),
        ("arms[0].grasp.x", "1", "arms[0].grasp.x"),
        ("simulation[0]", "1", "simulation[0]"),
        ("simulation..x", "1", "simulation..x"),
    ],
)
def test_override_unknown_path(tmp_path, path, value, named):
    with pytest.raises(ScenarioError) as info:
        load_scenario(write(tmp_path, base()), {path: value})
    assert named in str(info.value) and "\n" not in str(info.value)


def test_override_bad_value_names_path(tmp_path):
    raises("simulation.substeps", load_scenario, write(tmp_path, base()), {"simulation.substeps": "0"})
    raises("springs[0].stiffness", load_scenario, write(tmp_path, base()), {"springs[0].stiffness": "nan"})


def test_override_can_fix_a_bad_file(tmp_path):
    path = write(tmp_path, _set(base(), "simulation.substeps", 0))
    assert load_scenario(path, {"simulation.substeps": "2"}).simulation.substeps == 2


@pytest.mark.parametrize(
    "text, value",
    [("1e6", 1e6), ("3", 3), ("[0,0.1,0]", [0, 0.1, 0]), ("rk4", "rk4"), ("true", True), ('"x y"', "x y"), ("{a = 1}", {"a": 1})],
)
def test_parse_override_value(text, value):
    assert parse_override_value(text) == value


# ---------------------------------------------------------------------- ranges of counts and sizes (issue 22)
def test_grasps_at_one_point_name_the_arm(tmp_path, capsys):
    """Issue 22: grasps at the object's centre were reported as "r_contacts = (0, 1)"."""
    from coopctrl import cli

    data = Scenario().to_dict()
    data["arms"][0]["grasp"] = [0.0, 0.0, 0.0]
    data["arms"][1]["grasp"] = [0.0, 0.0, math.pi]
    assert cli.main(["check", str(write(tmp_path, data))]) == 2
    err = capsys.readouterr().err
    assert "arms[1].grasp = [0.0, 0.0, 3.14159" in err and "arms[0].grasp" in err and "r_contacts" not in err


def test_object_pose_noise_has_a_physical_range(capsys):
    """Issue 22: an object-pose noise of 1e6 m was reported as an infeasible load distribution."""
    from coopctrl import cli

    assert cli.main(["check", "--set", "sensors.object.noise_std=1e6"]) == 2
    err = capsys.readouterr().err
    assert "sensors.object.noise_std = 1000000.0 is invalid" in err and "<= 0.1 [m or rad]" in err
    assert scenario_from_dict({"sensors": {"object": {"noise_std": 0.1}, "forces": {"noise_std": 1e3}}})
    for channel, value in (("joints", 0.11), ("forces", 1001.0), ("object", 0.2)):
        with pytest.raises(ScenarioError, match=rf"sensors\.{channel}\.noise_std"):
            scenario_from_dict({"sensors": {channel: {"noise_std": value}}})


@pytest.mark.parametrize("path, value, message", [
    ("load_distribution.friction_facets", 10**9, "<= 64"),
    ("load_distribution.friction_facets", 2, ">= 3"),
    ("load_distribution.max_iter", 10**7, "<= 100000"),
    ("load_distribution.max_consecutive_failures", 0, ">= 1"),
    ("simulation.seed", 2**63, "<= 9223372036854775807"),
    ("simulation.substeps", 10001, "<= 10000"),
])
def test_counts_have_ranges(path, value, message):
    with pytest.raises(ScenarioError, match=path.replace(".", r"\.")) as err:
        load_scenario(None, {path: str(value)})
    assert message in str(err.value)


def test_arm_count_via_count_and_dh_rows_are_bounded():
    from coopctrl.scenario.scenario import MAX_ARMS, MAX_VIA_POINTS

    arms = [{"model": "planar3r", "role": "leader" if k == 0 else "follower", "base": [k, 0, 0],
             "grasp": [0.01 * k, 0, 0]} for k in range(MAX_ARMS + 1)]
    with pytest.raises(ScenarioError, match=rf"arms = '17 tables' is invalid: expected a list of 2 to {MAX_ARMS}"):
        scenario_from_dict({"arms": arms})
    via = [{"time": 0.001 * k, "pose": [0.0, 0.5, 0.0]} for k in range(MAX_VIA_POINTS + 1)]
    with pytest.raises(ScenarioError, match=r"trajectory\.via = '10001 points'"):
        scenario_from_dict({"trajectory": {"via": via}})
    row = [0.1, 0, 0, 0, 1, 0, 0, 0, 0.01, 0.01, 0.01, 0, 0, 0]
    from coopctrl.scenario.arm import MAX_DH_JOINTS

    with pytest.raises(ScenarioError, match=rf"dh = '{MAX_DH_JOINTS + 1} rows' is invalid: expected a list of 1 to {MAX_DH_JOINTS} rows"):
        ArmConfig(model="dh", role="leader", base=[0] * 6, grasp=[0] * 6, dh=[row] * (MAX_DH_JOINTS + 1))


def test_urdf_chain_count_refuses_cycles_and_entities(tmp_path):
    """The joint count read at load (scenario/arm.py) stops on a cycle of links and refuses entity
    declarations (defusedxml) instead of looping or expanding them."""
    from coopctrl.scenario.arm import urdf_chain_dof

    cycle = tmp_path / "cycle.urdf"
    cycle.write_text('<robot name="c"><link name="base"/><link name="a"/><link name="b"/>'
                     '<joint name="j1" type="revolute"><parent link="a"/><child link="b"/></joint>'
                     '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint></robot>')
    with pytest.raises(ScenarioError, match="form a cycle"):
        urdf_chain_dof(str(cycle), "base", "b")
    laughs = tmp_path / "laughs.urdf"
    laughs.write_text('<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;">'
                      ']><robot name="&b;"><link name="base"/></robot>')
    with pytest.raises(ScenarioError, match="without a document type declaration, entities"):
        urdf_chain_dof(str(laughs), "base", "base")


def test_check_says_which_rotations_a_scene_takes_and_why(tmp_path):
    """``coopctrl check``'s last words (coopctrl.scenario.scenario.rotations_text): charts, or the book's angles
    with the spring that keeps the scene in them."""
    from coopctrl.scenario.scenario import rotations_text

    assert rotations_text(load_scenario(write(tmp_path, spatial()))) == "rotations in charts (any pitch)"
    kept = rotations_text(load_scenario(write(tmp_path, with_springs(spatial(), damping_form="book",
                                                                     torsion_damping=0.05))))
    assert kept.startswith("rotations in the book's world angles (springs[0].damping_form = 'book'; charts need")
    assert rotations_text(Scenario()) == ""  # planar: one angle, nothing to say
