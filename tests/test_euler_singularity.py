"""The ZYX Euler-angle singularity (docs/model.md s.2, issue 5): detected on the nominal path before a run
(bad input, exit 2) and in the running state (status "diverged" with the singularity as the reason)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from coopctrl.analysis.euler_singularity import (
    EULER_PITCH_MARGIN_DEG,
    check_nominal_path,
    first_path_hit,
    nominal_path_pitches,
)
from coopctrl.errors import ScenarioError
from coopctrl.scenario import build, load_scenario
from coopctrl.simulator import closed_loop
from coopctrl.trajectory import MinimumJerkTrajectory
from plants.errors import EulerSingularityError
from plants.frames import rotation_zyx
from test_cli import REPO, assert_user_error, coopctrl

GRASPS = np.array([[-0.15, 0.0, 0.0, 0.0, 0.0, 0.0], [0.15, 0.0, 0.0, math.pi, 0.0, 0.0]])


def path(*pitches, times=None):
    times = times or [2.0 * k for k in range(len(pitches))]
    poses = [[0.0, 0.0, 0.5, 0.0, th, 0.0] for th in pitches]
    return MinimumJerkTrajectory(times, poses, "spatial")


# ---------------------------------------------------------------------- the nominal path
def test_node_pitch_formula_matches_rotation_matrices():
    """The vectorised node pitch (row 2 of R_0 times column 0 of R_grasp) against full rotation matrices."""
    traj = MinimumJerkTrajectory([0.0, 1.0], [[0, 0, 0.5, 0.3, -0.2, 0.4], [0, 0, 0.5, -1.0, 1.1, 2.0]], "spatial")
    grasps = np.array([[0.1, 0, 0, 0.2, 0.5, -0.3], [0, 0.1, 0, 2.0, -0.4, 1.0]])
    t = np.linspace(0.0, 1.0, 7)
    theta, cos = nominal_path_pitches(traj, grasps, t)
    Y0 = traj.sample(t)[0]
    for k in range(t.size):
        R0 = rotation_zyx(Y0[k, 3:6])
        for j, g in enumerate(grasps):
            R = R0 @ rotation_zyx(g[3:6])
            assert theta[k, j + 1] == pytest.approx(math.asin(-R[2, 0]), abs=1e-12)
            assert cos[k, j + 1] == pytest.approx(math.hypot(R[2, 1], R[2, 2]), abs=1e-12)


def test_path_crossing_the_singularity_between_clear_via_points_is_found():
    """Via poses at pitch 0 and 100 deg are both clear of +-90 deg (|cos| = 1 and 0.17); the minimum-jerk
    path between them crosses it (the old per-via check only looked at the vias)."""
    found = first_path_hit(path(0.0, math.radians(100.0)), GRASPS)
    assert found is not None
    hit, segment = found
    assert segment == 0
    assert hit.cos_theta < 0.005  # the samples are at most 0.25 deg apart: |cos| <= sin(0.25 deg) / 2 + ...
    assert 0.0 < hit.time < 2.0
    with pytest.raises(ScenarioError) as info:
        check_nominal_path(path(0.0, math.radians(100.0)), GRASPS)
    assert info.value.path == "trajectory.via[1].pose"
    assert "Euler-angle singularity" in str(info.value) and "keep |pitch| below 85 deg" in str(info.value)


def test_contact_node_pitched_by_its_grasp_is_found():
    """The object pitches to 50 deg only, but a grasp pitched 40 deg puts its node at 90 deg."""
    grasps = GRASPS.copy()
    grasps[0, 4] = math.radians(40.0)
    found = first_path_hit(path(0.0, math.radians(50.0)), grasps)
    assert found is not None and found[0].node == 1
    assert abs(found[0].pitch_deg) > 90.0 - EULER_PITCH_MARGIN_DEG
    assert first_path_hit(path(0.0, math.radians(50.0)), GRASPS) is None


@pytest.mark.parametrize("deg, refused", [(84.0, False), (86.0, True), (-86.0, True), (0.0, False)])
def test_margin_is_five_degrees(deg, refused):
    assert (first_path_hit(path(0.0, math.radians(deg)), GRASPS) is not None) == refused


def test_single_pose_path_is_checked():
    with pytest.raises(ScenarioError, match=r"trajectory\.via\[0\]\.pose"):
        check_nominal_path(path(math.radians(88.0)), GRASPS)


# ---------------------------------------------------------------------- bad input before a run
NEAR = {"trajectory.via[1].pose": "[0, 0, 0.6, 0, 1.53, 0]"}  # 87.7 deg at t = 2 s
#: The shipped scene as it was before rotation charts (issue 20): the book's world angles, an Euler-angle
#: path from 75 to 83 deg, the book's rotation and damping forms (its comment shows these --set).
BOOK = {"scene.rotations": '"book"', "trajectory.orientation": '"euler"', "trajectory.via[1].pose": "[0, 0, 0.6, 0, 1.45, 0]",
        "springs[0].rotation_form": '"book"', "springs[1].rotation_form": '"book"',
        "springs[0].damping_form": '"book"', "springs[1].damping_form": '"book"'}


def book_sets(**more) -> list[str]:
    """``--set`` arguments of :data:`BOOK` updated with ``more`` (path: value text)."""
    out = []
    for key, value in {**BOOK, **more}.items():
        out += ["--set", f"{key}={value}"]
    return out


@pytest.mark.parametrize("command", ["check", "run"])
def test_cli_refuses_a_path_near_the_singularity(command):
    proc = coopctrl(command, "euler_singularity", *book_sets(**NEAR))
    assert_user_error(proc, "trajectory.via[1].pose", "Euler-angle singularity", "87.66 deg", "cos(theta)",
                      "keep |pitch| below 85 deg")


def test_unloaded_start_is_checked_too():
    """`check` of an unloaded start never builds the loaded state; the path is still checked."""
    proc = coopctrl("check", "euler_singularity", "--set", "simulation.start=unloaded", *book_sets(**NEAR))
    assert_user_error(proc, "trajectory.via[1].pose")


# ---------------------------------------------------------------------- in a run
def test_shipped_scene_in_the_book_angles_stops_as_approaching_the_singularity():
    """The shipped scene in the book's angles (BOOK) carries the box at pitch 75 deg: the torsion damping, in
    Euler-angle rates, acts on an inertia ~ cos^2(75 deg) = 0.067 of the upright one, RK4 at 1 ms is past its
    limit and the run stops naming the singularity, the pitch, the stiff mode and the fix (not a bare
    'diverged')."""
    from coopctrl.scenario.loader import parse_override_value

    overrides = {key: parse_override_value(value) for key, value in BOOK.items()}
    scenario = load_scenario(REPO / "scenarios" / "euler_singularity.toml", {**overrides, "simulation.duration": 0.1})
    loop = closed_loop(scenario)
    rec = loop.run(build.initial_state(scenario), 0.1)
    assert rec["status"] == "diverged"
    reason = rec["reason"]
    assert "approaching the Euler-angle singularity" in reason and "pitch theta = " in reason
    assert "cos(theta)" in reason and "keep |pitch|" in reason and "at t = " in reason
    assert [e[1] for e in rec["events"]] == ["euler_singularity"]
    # the mode blamed is the chart's: about 1/cos^2 = 15 times the upright fastest mode (447 rad/s)
    stiff = float(reason.split("the mode that limits rk4 there (")[1].split(" rad/s")[0])
    assert stiff > 10 * 447.0
    assert np.all(np.isfinite(rec["x"]))


def test_drift_into_the_singularity_stops_the_run():
    """A passive, undamped contact-point assembly set spinning about y at 3 rad/s from pitch 0: the run
    stops when a node's pitch enters the 5 deg band, at t = 85 deg / 3 rad/s ~ 0.49 s, with status
    "diverged" and an "euler_singularity" event naming the node, the angle and cos(theta).
    The step (0.25 ms) keeps RK4 inside its limit up to the band: the undamped chart mode there is
    ~ 470 / cos(85 deg) = 5400 rad/s, RK4's limit 0.52 ms."""
    overrides = {"controllers.enabled": "false", "simulation.substeps": "4", "scene.gravity": "0",
                 "scene.rotations": "book",  # the book's world angles (in charts, the default, it spins through)
                 **{f"springs[{i}].{k}": "0" for i in (0, 1) for k in ("damping", "torsion_damping")}}
    scenario = load_scenario(REPO / "scenarios" / "contact_points_only.toml", overrides)
    loop = closed_loop(scenario)
    plant = loop.plant
    x0 = build.initial_state(scenario)
    nz, omega = plant.nz, 3.0
    Y = plant.node_poses(x0).reshape(-1, 6)
    v = x0.copy()
    v[nz:] = 0.0
    for i in range(plant.arm_count):  # rigid rotation about the world y axis through the object's MC
        sl = plant.q_slice(i)
        d = Y[i + 1, :3] - Y[0, :3]
        v[nz:][sl][:3] = np.cross([0.0, omega, 0.0], d)
        v[nz:][sl.start + 4] = omega if abs(Y[i + 1, 3]) < 1.0 else -omega  # node 2 (yaw pi) pitches as -theta
    v[2 * nz - 2] = omega  # the object's pitch rate
    rec = loop.run(v, 1.0)
    assert rec["status"] == "diverged"
    assert rec["reason"].startswith("Euler-angle singularity at t = ")
    kinds = [e[1] for e in rec["events"]]
    assert kinds == ["euler_singularity"]
    t_hit = rec["events"][0][0]
    assert t_hit == pytest.approx(math.radians(90.0 - EULER_PITCH_MARGIN_DEG) / omega, rel=0.05)
    assert "cos(theta) = " in rec["reason"] and "a smaller step does not help" in rec["reason"]
    pitch = float(rec["reason"].split("pitch theta = ")[1].split(" deg")[0])
    assert 90.0 - EULER_PITCH_MARGIN_DEG - 1.0 < abs(pitch) < 90.0


def test_plant_singularity_inside_a_period_is_reported_as_such():
    """If the plant itself refuses a state (cos(theta) < 1e-6 inside a control period), the run reports the
    Euler-angle singularity with the node and the angle, not a generic plant error. The failure is
    injected through the plant's Python right-hand side, which an integrator outside the kernel calls
    (the plant then steps in Python between kernel calls); the kernel's own integration maps its
    status to the same exception."""
    from coopctrl.integrators import get_integrator

    class OutsideRK4:  # an integrator the kernel does not implement: RK4 stepped from Python
        name = "rk4_outside"

        def __init__(self):
            self.inner = get_integrator("rk4")

        def step(self, f, t, x, u, h):
            return self.inner.step(f, t, x, u, h)

        def __getattr__(self, attr):
            return getattr(self.inner, attr)

    scenario = load_scenario(REPO / "scenarios" / "contact_points_only.toml", {"simulation.duration": 0.05})
    loop = closed_loop(scenario, integrator=OutsideRK4())
    rhs = loop.plant.rhs

    def failing(t, x, tau):
        if t > 0.0105:
            raise EulerSingularityError("contact node 2 (arms[1])", math.pi / 2, 1e-7)
        return rhs(t, x, tau)

    loop.plant.rhs = failing
    try:
        rec = loop.run(build.initial_state(scenario), 0.05)
    finally:
        del loop.plant.rhs
    assert rec["status"] == "diverged"
    assert rec["reason"].startswith("Euler-angle singularity at t = 0.01")
    assert "contact node 2 (arms[1])" in rec["reason"] and "90.00 deg" in rec["reason"]
    assert rec["events"][-1][1] == "euler_singularity"
