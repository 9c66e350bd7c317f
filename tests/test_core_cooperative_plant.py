"""CooperativePlant's Python methods call the compiled core (plants._core): its entry points agree with one another
(the control terms, the node state and arm terms, the node poses and rates, bit for bit), the node frames of a
plant in the world chart are ``R(A)`` and its partials, the interconnection wrenches are the elastic system's
forces and the plant's contact wrenches (the Python sum over the edges), on shipped scenes' plants (also with the
arms' nodes in their own charts) and on small plants of contact points; and a script that calls every plants
entry point of a run imports no numba.

The bit-for-bit comparisons with the numba kernels these replaced (``plant.kernel``, ``control_kernel_into``)
went with them: they were run when the core was ported, and the golden records (tests/golden) lock a run's
numbers."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import _golden
import coopctrl
from _scenes import scene
from coopctrl.wiring import closed_loop
from plants import _core
from plants.errors import ParameterError
from plants.frames import rotation_zyx, rotation_zyx_partials

SCENES = ["spatial_two_puma_carry", "two_panda_flip", "contact_points_only", "flexible_bar_carry",
          "planar_two_arm_lift", "gripping_immobile_object"]
TERMS = ("Y", "dY", "H", "h", "J", "Jdq", "W", "w_free", "S", "Fw")
#: The interconnection terms against the elastic system's forces and the Python sum of the contact wrenches: the
#: same element forces summed in another order, a few ulps of the largest force.
SUM_RTOL = 1e-12


def _plants(name):
    """A shipped scene's plant, and its plant with the arms' nodes in their own charts where the scene allows."""
    plant = closed_loop(coopctrl.load_scenario(name)).plant
    out = [plant]
    if plant.space == "spatial" and plant.elastic.chart_dependence() is None:
        out.append(plant.with_charts(arm_charts="own"))
    return out


def _states(name, plant, rng):
    with np.load(_golden.path_of(name)) as record:
        xs = [record["x"][k] for k in (0, len(record["x"]) // 2, -1)]
    return [(x + rng.normal(scale=1e-3, size=x.shape), rng.normal(scale=5.0, size=plant.input_size)) for x in xs]


def _assert_entry_points_agree(plant, x, tau):
    """control_terms, arm_terms, node_poses and node_velocities: one set of numbers (separate core entry points);
    the right-hand side's first half is the state's rates."""
    ct = plant.control_terms(x)
    for got, name in zip(plant.arm_terms(x), TERMS[:6]):
        np.testing.assert_array_equal(got, getattr(ct, name), err_msg=name)
    np.testing.assert_array_equal(plant.node_poses(x), ct.Y.reshape(-1))
    np.testing.assert_array_equal(plant.node_velocities(x), ct.dY.reshape(-1))
    dx = plant.rhs(0.0, x, tau)
    np.testing.assert_array_equal(dx[:plant.nz], x[plant.nz:])
    assert np.all(np.isfinite(dx))


@pytest.mark.parametrize("name", SCENES)
def test_the_plants_entry_points_agree_on_shipped_scenes(name):
    rng = np.random.default_rng(len(name))
    for plant in _plants(name):
        for x, tau in _states(name, plant, rng):
            _assert_entry_points_agree(plant, x, tau)


@pytest.mark.parametrize("space,arms", [("spatial", "contact"), ("planar", "contact"), ("planar", "full")])
def test_the_plants_entry_points_agree_on_small_plants(space, arms):
    plant, x0 = scene(space, m=3 if space == "planar" else 2, arms=arms, damping=3.0, torsion_damping=0.2)
    rng = np.random.default_rng(3)
    for _ in range(4):
        x = x0 + rng.normal(scale=0.02, size=x0.shape)
        _assert_entry_points_agree(plant, x, rng.normal(size=plant.input_size))


@pytest.mark.parametrize("name", ["two_panda_flip", "spatial_two_puma_carry", "planar_two_arm_lift"])
def test_the_node_state_binding_gives_the_arm_terms_and_the_node_frames(name):
    """_core.spatial_node_state / planar_node_state (the plant's node poses, arm terms and, in space, every node's
    frames in its chart: what book_coordinates, energy and contact_wrenches read): the plant's arm terms, and in
    the world chart each node's frames ``R(A)`` and its three partials."""
    rng = np.random.default_rng(7)
    for plant in _plants(name):
        P = plant.plant_args
        for x, _tau in _states(name, plant, rng):
            got = (_core.spatial_node_state if plant.space == "spatial" else _core.planar_node_state)(x, P)
            assert tuple(got["status"]) == (0, 0)
            for name_, arr in zip(TERMS[:6], plant.arm_terms(x)):
                np.testing.assert_array_equal(got[name_], arr, err_msg=name_)
            if plant.space == "spatial" and not plant.charted:
                for k, A in enumerate(got["Y"][:, 3:]):
                    np.testing.assert_allclose(got["frames"][k, 0], rotation_zyx(A), rtol=0.0, atol=1e-15)
                    for i, dR in enumerate(rotation_zyx_partials(A)):
                        np.testing.assert_allclose(got["frames"][k, 1 + i], dR, rtol=0.0, atol=1e-15)


def _assert_wrenches_are_the_forces(plant, Y, dY):
    """``S``: the elastic system's ``dPi/dY + dD/d(dY)``; ``Fw``: finite, and returned (compared by the callers)."""
    S, Fw = plant.interconnection_wrenches(Y, dY)
    want = (plant.elastic.elastic_force(Y.reshape(-1)) + plant.elastic.damping_force(Y.reshape(-1), dY.reshape(-1)))
    np.testing.assert_allclose(S.reshape(-1), want, rtol=0.0, atol=SUM_RTOL * (1.0 + np.abs(want).max()))
    assert np.all(np.isfinite(Fw))
    return Fw


@pytest.mark.parametrize("name", SCENES)
def test_the_interconnection_wrenches_are_the_elastic_forces_and_the_contact_wrenches(name):
    rng = np.random.default_rng(11)
    for plant in _plants(name):
        for x, tau in _states(name, plant, rng):
            Y, dY, _ = plant.book_coordinates(x, plant.rhs(0.0, x, tau))  # the world angles, whatever the charts
            Y, dY = Y.reshape(plant.node_count, plant.p), dY.reshape(plant.node_count, plant.p)
            assert not plant.elastic.charted  # its own methods would read the angles in its charts
            Fw = _assert_wrenches_are_the_forces(plant, Y, dY)
            want = plant.contact_wrenches(x)
            np.testing.assert_allclose(Fw, want, rtol=0.0, atol=SUM_RTOL * (1.0 + np.abs(want).max()))
            S0, _ = plant.interconnection_wrenches(Y.reshape(-1))  # flat, at rest: dY = 0
            np.testing.assert_array_equal(S0, plant.interconnection_wrenches(Y, np.zeros_like(Y))[0])


@pytest.mark.parametrize("unloaded_state", ["mobile", "immobile"])
def test_the_interconnection_wrenches_in_both_models_and_at_the_objects_singularity(unloaded_state):
    plant, x0 = scene("spatial", m=2, arms="contact", damping=3.0, torsion_damping=0.2, node_springs=True,
                      unloaded_state=unloaded_state)
    rng = np.random.default_rng(5)
    Y = plant.node_poses(x0).reshape(plant.node_count, 6) + rng.normal(scale=0.01, size=(plant.node_count, 6))
    dY = rng.normal(size=Y.shape)
    assert np.any(_assert_wrenches_are_the_forces(plant, Y, dY))
    Y[0, 4] = np.pi / 2  # the object at pitch 90 deg: no wrench on it is defined
    np.testing.assert_array_equal(plant.interconnection_wrenches(Y, dY)[1], 0.0)
    with pytest.raises(ParameterError, match="Y"):
        plant.interconnection_wrenches(Y[1:])


@pytest.mark.parametrize("name", ["spatial_two_puma_carry", "planar_two_arm_lift", "flexible_bar_carry"])
def test_a_stack_of_node_poses_gives_each_samples_wrenches_bit_for_bit(name):
    """``interconnection_wrenches`` of a stack (B, m + 1, p) is each sample's own call, bit for bit (the grasp
    compliance's finite differences make all their poses in one call), and a stack of the wrong width is refused."""
    rng = np.random.default_rng(23)
    plant = _plants(name)[0]
    x = next(iter(_states(name, plant, rng)))[0]
    Y0 = plant.book_coordinates(x, np.zeros_like(x))[0].reshape(plant.node_count, plant.p)
    Ys = Y0 + rng.normal(scale=1e-3, size=(5, *Y0.shape))
    dYs = rng.normal(scale=0.1, size=Ys.shape)
    S, Fw = plant.interconnection_wrenches(Ys, dYs)
    assert S.shape == Ys.shape and Fw.shape == (5, plant.arm_count, plant.p)
    for b in range(5):
        S_b, Fw_b = plant.interconnection_wrenches(Ys[b], dYs[b])
        np.testing.assert_array_equal(S[b], S_b)
        np.testing.assert_array_equal(Fw[b], Fw_b)
    np.testing.assert_array_equal(plant.interconnection_wrenches(Ys)[0][2], plant.interconnection_wrenches(Ys[2])[0])
    with pytest.raises(ParameterError, match="Y"):
        plant.interconnection_wrenches(Ys[:, 1:])
    with pytest.raises(ValueError, match="^dY: expected the shape of Y"):
        _core.spatial_interconnection_wrenches(Ys, dYs[:2], plant.plant_args) if plant.p == 6 else \
            _core.planar_interconnection_wrenches(Ys, dYs[:2], plant.plant_args)


_SCRIPT = """
import sys
import numpy as np
sys.path.insert(0, sys.argv[1])
from _scenes import scene
from plants import charts, frames
from plants.cooperative import nominal_node_motion

for space, arms in (("spatial", "full"), ("spatial", "contact"), ("planar", "full")):
    plant, x0 = scene(space, m=2, arms=arms, damping=2.0)
    x = x0 + 1e-3
    tau = np.zeros(plant.input_size)
    dx = plant.rhs(0.0, x, tau)
    plant.control_terms(x), plant.arm_terms(x), plant.node_poses(x), plant.node_velocities(x)
    plant.mass_matrix(x), plant.energy(x), plant.contact_wrenches(x), plant.leader_follower(x)
    plant.book_coordinates(x, dx), plant.interconnection_wrenches(plant.node_poses(x)), plant.jacobians(x, tau)
    Y, dY = plant.node_poses(x), plant.node_velocities(x)
    plant.elastic.accelerations(Y, dY, np.zeros_like(Y)), plant.elastic_potential(Y), plant.elastic_force(Y)
    if space == "spatial":
        own = plant.with_charts(arm_charts="own") if plant.elastic.chart_dependence() is None else plant
        own.energy(x), own.contact_wrenches(x), own.book_coordinates(x, own.rhs(0.0, x, tau))
        moved, xm = plant.recentred(x)
        moved.energy(xm), moved.chart_cos(xm), moved.control_terms(xm)
        A = np.array([0.1, 0.2, 0.3])
        frames.rotation_zyx(A), frames.body_rate_map(A), frames.body_rate_map_dot(A, A), frames.body_rate_map_inv(A)
        frames.euler_zyx_from_rotation(frames.rotation_zyx(A)), frames.rotation_zyx_partials(A)
        charts.recentre(np.eye(3), A, A), charts.world_coordinates(np.eye(3), A, A, A)
        nominal_node_motion(np.zeros(6), A.repeat(2), A.repeat(2), np.zeros((2, 6)))
        if arms == "full":
            arm = plant.arms[0]
            arm.terms(x[plant.q_slice(0)], x[plant.q_slice(0)]), arm.tip_transform(x[plant.q_slice(0)])
            arm.inverse_kinematics(plant.node_poses(x)[6:12], x[plant.q_slice(0)])
    else:
        frames.rotation_planar(0.3)
print(sorted(m for m in sys.modules if m == "numba" or m.startswith("numba.")))
"""


def test_the_plants_entry_points_of_a_run_import_no_numba():
    tests = Path(__file__).resolve().parent
    out = subprocess.run([sys.executable, "-c", _SCRIPT, str(tests)], capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"
