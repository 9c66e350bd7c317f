"""The closed loop in rotation charts (coopctrl.loop.charts; scene.rotations = "charts"): a passive carry
whose object turns through pitch 90 deg runs ok with its energy conserved, the loop re-centring the
object's and contact points' charts; the same state in the book's world angles stops at the band."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.errors import ScenarioError
from coopctrl.loop.charts import WorldChart, book_view, continuous, euler_of, rotations_of, target_motion
from coopctrl.scenario import build
from coopctrl.scenario.loader import load_scenario
from coopctrl.simulator import closed_loop
from coopctrl.trajectory import GeodesicTrajectory
from coopctrl.trajectory.quaternion import from_zyx
from coopctrl.trajectory.quaternion import matrix as quat_matrix
from plants.cooperative import PlantArgs
from plants.frames import body_rate_map, rotation_zyx

SCENE = "scenarios/euler_singularity.toml"  # in charts, geodesic springs
DURATION = 0.2
#: No damping (energy conserved), controllers off, a fifth of a second.
PASSIVE = {"controllers.enabled": False, "simulation.duration": DURATION,
           **{f"springs[{k}].{key}": value for k in (0, 1)
              for key, value in (("damping", 0.0), ("torsion_damping", 0.0), ("damping_form", "frame_invariant"))}}
CHARTS = {"scene.rotations": "charts", "springs[0].rotation_form": "geodesic", "springs[1].rotation_form": "geodesic"}
#: Pitch rate of the rigid spin [rad/s]: from 1.309 rad (75 deg), 0.2 s turns the object to 132 deg.
SPIN = 5.0


def spinning_start(loop, scenario):
    """The scene's start with the object and contact points turning rigidly about world y at SPIN."""
    plant = loop.plant
    x0 = build.initial_state(scenario).copy()
    nz = plant.nz
    r0 = x0[nz - 6:nz - 3]
    w = np.array([0.0, SPIN, 0.0])
    # the object's and the contact points' coordinates: the last 6 of z, and each contact point's 6
    for start in [nz - 6] + [6 * i for i in range(plant.arm_count)]:
        r, A = x0[start:start + 3], x0[start + 3:start + 6]
        x0[nz + start:nz + start + 3] = np.cross(w, r - r0)
        x0[nz + start + 3:nz + start + 6] = np.linalg.solve(body_rate_map(A), rotation_zyx(A).T @ w)
    return x0


def test_a_passive_carry_turns_through_pitch_90_deg_in_charts_and_stops_in_the_book_angles():
    scenario = load_scenario(SCENE, {**PASSIVE, **CHARTS})
    loop = closed_loop(scenario)
    rec = loop.run(spinning_start(loop, scenario), DURATION)
    assert rec["status"] == "ok", rec["reason"]
    assert [e[1] for e in rec["events"]].count("chart_recentred") >= 2  # at the start (75 deg) and 45.6 deg later
    q = rec["object_rotation"]
    pitch = np.degrees(2.0 * np.arctan2(q[:, 2], q[:, 0]))  # a turn about y only: q = (cos a/2, 0, sin a/2, 0)
    assert pitch[0] == pytest.approx(np.degrees(1.309), abs=1e-9) and pitch[-1] > 125.0
    # the rigid spin stays about y: x and z parts of q are rounding (1e-12 of |q| = 1)
    assert np.max(np.abs(q[:, [1, 3]])) < 1e-12
    # energy: the re-centring is exact, so the drift is RK4's at h = 1 ms (measured 1e-6 of the kinetic
    # energy over 0.2 s); 1e-4 still catches a re-centring off by that much in the body rates
    E, T = rec["energy"], rec["kinetic_energy"]
    assert np.ptp(E) <= 1e-4 * np.max(T)
    # the record is in the book's world angles: they give the recorded rotation wherever they exist
    nz = loop.plant.nz
    A = rec["x"][:, nz - 3:nz]
    far = np.abs(np.cos(A[:, 1])) > 0.1
    qa = from_zyx(A[far])
    assert np.max(np.abs(np.abs(np.einsum("ij,ij->i", qa, q[far])) - 1.0)) < 1e-12
    # the book's angles at the same start: the loop's band guard stops the run before pitch 85 deg
    book = load_scenario(SCENE, {**PASSIVE, "scene.rotations": "book",  # its path to 105 deg: refused in the book's angles
                                 "trajectory.via[1].pose": [0.0, 0.0, 0.6, 0.0, 1.45, 0.0]})
    book_loop = closed_loop(book)
    rec_book = book_loop.run(spinning_start(book_loop, book), DURATION)
    assert rec_book["status"] == "diverged" and "Euler" in rec_book["reason"]


def test_the_trajectory_table_in_a_world_chart_is_the_euler_view_turned():
    """WorldChart.table: in the identity chart the rows are the trajectory's Euler view; in a chart C they are
    the Euler view of the turned targets (positions C^T r, angles of C^T R), the same body rates."""
    path = GeodesicTrajectory([0.0, 1.0], [[0, 0, 0.5, 0.3, 0.2, -0.1], [0.1, 0, 0.6, -0.4, 0.9, 0.5]])
    t = np.linspace(0.0, 1.0, 11)
    motion = target_motion(path, t)
    P = PlantArgs(arm_kind=np.array([1, 1]), arm_dof=None, q_off=np.array([0, 6]), tables=None, table_off=None,
                  bases=np.tile(np.eye(4), (2, 1, 1)), tools=None, gravity=np.array([0, 0, -9.81]), node_params=None,
                  edge_index=None, edge_params=None, Y_ref=None, immobile=False)  # what the chart reads
    chart = WorldChart(P, 18, motion)
    traj = np.zeros((3, 11, 6))
    chart.table(traj, 0)
    Y, dY, ddY = path.sample(t)
    # rounding of a few 3x3 products and atan2 (1e-12 rad and rad/s at rates below 2 rad/s)
    for a, b in zip(traj, (Y, dY, ddY)):
        assert np.max(np.abs(a - b)) < 1e-11
    chart.C = rotation_zyx(np.array([0.4, -0.7, 0.2]))
    chart.table(traj, 3)
    Aw, dAw = book_view(np.broadcast_to(chart.C, (8, 3, 3)), traj[0, 3:, 3:], traj[1, 3:, 3:])
    assert np.max(np.abs(Aw - Y[3:, 3:])) < 1e-12 and np.max(np.abs(dAw - dY[3:, 3:])) < 1e-12
    assert np.max(np.abs(traj[0, 3:, :3] @ chart.C.T - Y[3:, :3])) < 1e-15


@pytest.mark.parametrize("overrides, field", [
    ({"springs[0].element": "central", "springs[0].rotation_form": "book"}, "springs[0].rotation_form"),
    ({"springs[1].damping_form": "book"}, "springs[1].damping_form"),  # torsion_damping 0.5 on Euler rates
    ({**CHARTS, **PASSIVE, "springs[0].element": "central", "springs[0].stiffness": [2e4, 2e4, 1e4]},
     "springs[0].stiffness"),  # per world axis: not invariant under the rotation of the world chart
    ({"scene.rotations": "quaternions"}, "scene.rotations"),
])
def test_charts_are_refused_with_the_field_and_what_is_allowed(overrides, field):
    with pytest.raises(ScenarioError) as info:
        load_scenario(SCENE, {"controllers.enabled": False, **overrides})
    assert info.value.path == field and "\n" not in str(info.value)


def test_a_planar_scene_refuses_charts():
    with pytest.raises(ScenarioError, match=r"scene.rotations = 'charts' is invalid: expected 'book' in a planar scene"):
        load_scenario("scenarios/planar_two_arm_lift.toml", {"scene.rotations": "charts"})


def test_two_passive_pumas_run_the_same_in_charts_as_in_the_book_angles_far_from_the_band():
    """A level carry never re-centres the world chart: the same geodesic springs run the same in charts and in
    the book's angles (the trajectory table computed from the rotations instead of the Euler view)."""
    from coopctrl.simulator import simulate

    scene = "scenarios/spatial_two_puma_carry.toml"
    same = {"controllers.enabled": False, "simulation.duration": 0.2,
            "springs[0].rotation_form": "geodesic", "springs[1].rotation_form": "geodesic"}
    book = simulate(load_scenario(scene, {**same, "scene.rotations": "book"}))  # charts are the default
    charts = simulate(load_scenario(scene, {**same, "scene.rotations": "charts"}))
    assert book.status == charts.status == "ok"
    # rounding only, grown by the springs over 200 ticks (measured 3e-14 of the largest entry); 1e-10 still
    # catches any wrong term (1e-3 or more)
    for name in ("x", "Y0", "Y_nodes", "F_measured", "energy"):
        a, b = getattr(charts, name), getattr(book, name)
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(b)), name
    assert charts.object_rotation is not None and book.object_rotation is None


#: The contact-point carry in charts-ready form: geodesic springs, frame-invariant dampers, a geodesic path.
CARRY = {**CHARTS, "springs[0].damping_form": "frame_invariant", "springs[1].damping_form": "frame_invariant",
         "trajectory.orientation": "geodesic"}


def carry(start, end, duration):
    """The carry from ``start`` to ``end`` (poses) in ``duration`` [s]."""
    return {**CARRY, "simulation.duration": duration, "object.pose": start,
            "trajectory.via": [{"time": 0.0, "pose": start}, {"time": duration, "pose": end}]}


def test_the_controlled_carry_in_charts_agrees_with_the_book_angles_where_both_exist():
    """From pitch 50 deg (|cos| = 0.64: the world chart is re-centred on the object at t = 0, so the whole loop
    runs in a rotated world) to 57 deg, where the book's angles run too, with the same springs. The two
    runs differ because the controllers' laws are written on Euler coordinates (computed torque on the
    angle errors, the followers' pose increments), which differ between the charts at the size of the
    tracking errors: the paths agree to a small fraction of those errors."""
    from coopctrl.simulator import simulate

    overrides = carry([0, 0, 0.45, 0.2, 0.87, 0.1], [0.05, 0, 0.5, 0.3, 1.0, 0.0], 0.4)
    charts = simulate(load_scenario(SCENE, overrides))
    overrides["scene.rotations"] = "book"
    book = simulate(load_scenario(SCENE, overrides))
    assert charts.status == book.status == "ok"
    assert [e[1] for e in charts.events].count("chart_recentred") == 1
    err = book.summary()["object_position_error_max_m"]
    # measured: the object's paths differ by 3e-6 m, 7 % of the book's tracking error (4e-5 m) and the contact
    # wrenches by 6e-5 of their size; a wrong rotation of any recorded or held quantity shows at 100 %
    assert np.max(np.abs(charts.Y0[:, :3] - book.Y0[:, :3])) <= 0.25 * err
    assert np.max(np.abs(charts.F_measured - book.F_measured)) <= 1e-3 * np.max(np.abs(book.F_measured))
    assert charts.summary()["object_position_error_rms_m"] == pytest.approx(book.summary()["object_position_error_rms_m"],
                                                                            rel=0.05)


def test_the_controlled_carry_passes_pitch_90_deg_in_charts_and_is_refused_in_the_book_angles():
    from coopctrl.simulator import simulate

    overrides = carry([0, 0, 0.45, 0, 1.309, 0], [0, 0, 0.6, 0, 1.83, 0], 0.5)  # 75 deg to 104.9 deg in 0.5 s
    result = simulate(load_scenario(SCENE, overrides))
    assert result.status == "ok", result.reason
    q = result.object_quaternion
    pitch = np.degrees(2.0 * np.arctan2(q[:, 2], q[:, 0]))
    assert pitch[-1] == pytest.approx(np.degrees(1.83), abs=0.1) and np.any(np.abs(pitch - 90.0) < 0.5)
    assert result.summary()["object_position_error_rms_m"] <= 2e-3  # the carry's level (issue 20: <= 2 mm)
    overrides["scene.rotations"] = "book"
    with pytest.raises(ScenarioError, match=r"trajectory.via\[1\].pose .* ZYX pitch stays at least 5 deg away"):
        closed_loop(load_scenario(SCENE, overrides))


def test_two_pandas_tip_the_box_past_its_side_in_charts():
    """The shipped flip (scenarios/two_panda_flip.toml): 100 deg of pitch about the grasp line under control,
    at the carry's accuracy; the book's angles refuse its path."""
    from coopctrl.simulator import simulate

    scenario = load_scenario("scenarios/two_panda_flip.toml")
    result = simulate(scenario)
    assert result.status == "ok", result.reason
    assert [e[1] for e in result.events].count("chart_recentred") == 2  # at 45.6 deg and at 91 deg
    R = quat_matrix(result.object_quaternion)
    up = R[:, 2, 2]  # the box's z axis, world z component: 1 upright, 0 on its side, < 0 past it
    assert up[0] == pytest.approx(1.0, abs=1e-9) and up[-1] == pytest.approx(np.cos(1.75), abs=1e-3)
    summary = result.summary()
    assert summary["object_position_error_rms_m"] <= 2e-3 and summary["max_torque_ratio"] < 1.0  # issue 20: <= 2 mm
    with pytest.raises(ScenarioError, match=r"trajectory.via\[1\].pose .* ZYX pitch stays at least 5 deg away"):
        closed_loop(load_scenario("scenarios/two_panda_flip.toml", {"scene.rotations": "book"}))


def test_the_recorded_angles_are_continuous_through_pitch_90_deg_and_across_pi():
    """The book's angles of a turn through pitch 90 deg (principal angles jump by pi in psi and phi there) and
    of a yaw through pi (a jump of 2 pi) come back as the continuous angles that made the rotations."""
    t = np.linspace(0.0, 1.0, 201)
    A = np.stack([2.8 + 0.8 * t, 1.2 + 0.7 * t, -0.3 + 0.4 * t], axis=1)  # psi through pi, theta through pi/2
    principal = euler_of(rotations_of(A))
    assert np.max(np.abs(np.diff(principal, axis=0))) > 3.0  # the jumps the record must not show
    # rounding of atan2 on rotations (1e-12 rad) except within 1e-6 rad of the singularity, none sampled here
    assert np.max(np.abs(continuous(principal, A[0]) - A)) < 1e-9
    shifted = A + np.array([2.0 * np.pi, 0.0, -2.0 * np.pi])
    assert np.max(np.abs(continuous(principal, shifted[0]) - shifted)) < 1e-9  # the start's whole turns kept


def test_the_loop_refuses_a_plant_in_its_own_charts():
    """The loop's charts are its world chart (rotations = 'charts'); a plant whose nodes take per-node charts
    would feed chart coordinates to controllers written on the book's angles: refused, naming the fix."""
    from coopctrl.closed_loop import ClosedLoop
    from coopctrl.loop.parts import LoopControllers, LoopGuards, LoopTiming

    scenario = load_scenario(SCENE, {**PASSIVE})
    loop = closed_loop(scenario)
    with pytest.raises(ValueError, match=r"plant is in rotation charts .* rotations = 'charts'"):
        ClosedLoop(loop.plant.with_charts(arm_charts="own"), loop.trajectory, loop.grasps, loop.ld,
                   LoopControllers(loop.leader, loop.followers, loop.compliance), loop.sensors,
                   LoopTiming(loop.integrator, loop.T, loop.substeps), LoopGuards(loop.max_deformation))


def test_a_run_in_charts_ends_in_the_book_coordinates_it_started_in():
    """``record.final_state`` of a run that re-centred its world chart is in the book's world coordinates, as
    the record: its state is the record's last one (and that of the same run made one tick longer), and its
    followers' integrals are the record's ``T sum (F* - F_measured)`` (the linearizer reads them)."""
    scenario = load_scenario("scenarios/two_panda_flip.toml")  # exact sensors
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    T = loop.T
    short = loop.run(x0, 2.2)  # past pitch 90 deg: two re-centrings (45.6 and 91 deg)
    longer = loop.run(x0, 2.2 + T)
    assert [e[1] for e in short["events"]].count("chart_recentred") == 2
    n = len(short["t"])  # ticks 0 .. N: the record's last row is the state the run ends in
    final = short["final_state"]
    # the same ticks in both runs; the last state is turned back by the last chart alone, the record by
    # batched products of the same 3x3 matrices: equal up to a few roundings, 1e-12 relative
    for x_end in (short["x"][-1], longer["x"][n - 1]):
        assert np.linalg.norm(final.x - x_end) <= 1e-12 * np.linalg.norm(x_end)
    follower = next(i for i in range(len(scenario.arms)) if i != scenario.leader)
    e = short["F_commanded"][:, follower, :] - short["F_measured"][:, follower, :]
    expected = T * e.sum(axis=0)  # every recorded tick's error, each turned back into the world by its chart
    # the kernel sums in the charts of the ticks, 2200 terms: rounding (1e-12) far below the 1e-9 relative
    # bound, and a frame left turned (the last chart is 100 deg from the world) would give order 1
    assert np.linalg.norm(final.integrals[follower] - expected) <= 1e-9 * np.linalg.norm(expected)


def test_a_python_integrator_steps_the_same_turned_world_as_the_kernel():
    """The reference integrator (scipy's DOP853, stepped in Python between kernel calls) runs in charts on the
    run's turned plant (CooperativePlant.with_own_world): the passive spin through pitch 90 deg conserves its
    energy across the re-centrings and turns as the compiled RK4 run does."""
    from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator

    scenario = load_scenario(SCENE, {**PASSIVE, **CHARTS})
    reference = closed_loop(scenario, integrator=ReferenceIntegrator(ReferenceConfig(rtol=1e-10, atol=1e-12)))
    rec = reference.run(spinning_start(reference, scenario), DURATION)
    assert rec["status"] == "ok", rec["reason"]
    assert [e[1] for e in rec["events"]].count("chart_recentred") >= 2
    # DOP853 at rtol 1e-10 over 200 periods: drift measured 1.5e-14 of the kinetic energy; the Python steps on
    # the world's gravity and bases (not turned with the chart) give 0.66
    E, T = rec["energy"], rec["kinetic_energy"]
    assert np.ptp(E) <= 1e-8 * np.max(T)
    rk4 = closed_loop(scenario)
    q_rk4 = rk4.run(spinning_start(rk4, scenario), DURATION)["object_rotation"]
    # RK4 at h = 1 ms against the reference: 6e-7 measured (quaternion distance, about half the angle in rad);
    # 1e-5 catches a re-centring whose rates are off by more than RK4's error
    assert np.max(np.linalg.norm(rec["object_rotation"] - q_rk4, axis=1)) < 1e-5


@pytest.mark.parametrize("grasp, when", [
    ([-0.15, 0.0, 0.0, 0.0, 1.55, np.pi], "at t = 0 s"),  # two_panda_carry's grasp pitched to 88.8 deg
    (None, "at t = 0.9"),  # the flip's second grasp turned square to its axis: in the band on the way
])
def test_a_grasp_whose_node_enters_the_band_in_the_objects_chart_is_refused_before_the_run(grasp, when):
    """In charts the contact nodes' angles are taken in the world chart centred on the object: a grasp whose
    node reaches the band there on the nominal path is bad input naming the grasp (the run would stop at the
    band: 0.883 s for the flip's case, measured with the check removed), refused before anything is built."""
    if grasp is None:
        scene, path, grasp = "two_panda_flip", "arms[1].grasp", [0.0, -0.15, 0.0, 0.0, 0.8, np.pi]
    else:
        scene, path = "two_panda_carry", "arms[0].grasp"
    scenario = load_scenario(scene, {path: grasp})
    assert scenario.scene.rotations == "charts"
    with pytest.raises(ScenarioError, match=r"contact node \d reaches pitch .* deg " + when) as info:
        build.check_path(scenario)
    assert info.value.path == path and "\n" not in str(info.value)
    with pytest.raises(ScenarioError):
        closed_loop(scenario)
