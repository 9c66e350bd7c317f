"""The closed loop in rotation charts (coopctrl.loop.charts; scene.rotations = "charts"): a passive carry
whose object turns through pitch 90 deg runs ok with its energy conserved, the loop re-centring the
object's and contact points' charts; the same state in the book's world angles stops at the band."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl.errors import ScenarioError
from coopctrl.loop.charts import book_view, own_chart_table, target_motion
from coopctrl.scenario import build
from coopctrl.scenario.loader import load_scenario
from coopctrl.simulator import closed_loop
from coopctrl.trajectory import GeodesicTrajectory
from coopctrl.trajectory.quaternion import from_zyx
from plants.frames import body_rate_map, rotation_zyx

SCENE = "scenarios/euler_singularity.toml"
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
    book = load_scenario(SCENE, PASSIVE)
    book_loop = closed_loop(book)
    rec_book = book_loop.run(spinning_start(book_loop, book), DURATION)
    assert rec_book["status"] == "diverged" and "Euler" in rec_book["reason"]


def test_the_trajectory_table_in_its_own_charts_is_the_euler_view_where_that_exists():
    path = GeodesicTrajectory([0.0, 1.0], [[0, 0, 0.5, 0.3, 0.2, -0.1], [0.1, 0, 0.6, -0.4, 0.9, 0.5]])
    t = np.linspace(0.0, 1.0, 11)
    motion = target_motion(path, t)
    table = own_chart_table(motion)
    assert np.array_equal(table[0, :, 3:], np.zeros((11, 3)))
    Y, dY, ddY = path.sample(t)
    Aw, dAw = book_view(motion[3], table[0, :, 3:], table[1, :, 3:])
    # rounding of a few 3x3 products and atan2 (1e-12 rad and rad/s at rates below 2 rad/s)
    assert np.max(np.abs(Aw - Y[:, 3:])) < 1e-12 and np.max(np.abs(dAw - dY[:, 3:])) < 1e-12
    assert np.array_equal(table[0, :, :3], Y[:, :3])


@pytest.mark.parametrize("overrides, field", [
    ({"scene.rotations": "charts"}, "springs[0].rotation_form"),
    ({**CHARTS, "springs[0].damping_form": "frame_invariant"}, "springs[1].damping_form"),  # the file: book dampers
    ({**CHARTS, **PASSIVE, "controllers.enabled": True}, "scene.rotations"),
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
    """The same geodesic springs in the book's angles and in charts (the arms' nodes in their own charts, the
    object's chart the identity: the carry stays level) are one system in two sets of coordinates: the
    record (given back in the book's angles), the node poses, the forces and the loop's energy agree."""
    from coopctrl.simulator import simulate

    scene = "scenarios/spatial_two_puma_carry.toml"
    same = {"controllers.enabled": False, "simulation.duration": 0.2,
            "springs[0].rotation_form": "geodesic", "springs[1].rotation_form": "geodesic"}
    book = simulate(load_scenario(scene, same))
    charts = simulate(load_scenario(scene, {**same, "scene.rotations": "charts"}))
    assert book.status == charts.status == "ok"
    # rounding only (the charts multiply the node frames by R_tip), grown by the springs over 200 ticks:
    # measured 3e-14 of the largest entry; 1e-10 still catches any wrong term (1e-3 or more)
    for name in ("x", "Y0", "Y_nodes", "F_measured", "energy"):
        a, b = getattr(charts, name), getattr(book, name)
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(b)), name
    assert charts.object_rotation is not None and book.object_rotation is None
