"""CooperativePlant's Python methods call the compiled core (plants._core), not numba: the right-hand side, the node
state and arm terms, the control terms, the node frames of a plant in charts and the workspaces give the numbers
of the numba kernels they replace (``plant.kernel``, ``plant.control_kernel_into``, plants.cooperative's
``*_kernel`` modules), bit for bit, on shipped scenes' plants (also with the arms' nodes in their own charts) and
on small plants of contact points; and a script that calls every plants entry point of a run compiles no numba
function of plants."""

from __future__ import annotations

import os
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
from plants.cooperative import _planar_kernel as numba_planar
from plants.cooperative import _spatial_kernel as numba_spatial

SCENES = ["spatial_two_puma_carry", "two_panda_flip", "contact_points_only", "flexible_bar_carry",
          "planar_two_arm_lift", "gripping_immobile_object"]
TERMS = ("Y", "dY", "H", "h", "J", "Jdq", "W", "w_free", "S", "Fw")


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


def _assert_calls_match(plant, x, tau):
    fn, args = plant.kernel
    want = fn(x, tau, *args)
    assert args[-1][0] == 0
    np.testing.assert_array_equal(plant.rhs(0.0, x, tau), want)
    cfn, cargs = plant.control_kernel_into
    cws = plant.control_workspace()
    cfn(x, *cargs, cws)
    assert cargs[-1][0] == 0
    ct = plant.control_terms(x)
    numba_terms = dict(Y=cws.ws.Y, dY=cws.ws.dY, H=cws.ws.H, h=cws.ws.h, J=cws.ws.J, Jdq=cws.ws.Jdq, W=cws.W,
                       w_free=cws.w_free, S=cws.S, Fw=cws.Fw)
    for name in TERMS:
        np.testing.assert_array_equal(getattr(ct, name), numba_terms[name], err_msg=name)
    for got, name in zip(plant.arm_terms(x), TERMS[:6]):
        np.testing.assert_array_equal(got, numba_terms[name], err_msg=name)
    np.testing.assert_array_equal(plant.node_poses(x), cws.ws.Y.reshape(-1))
    np.testing.assert_array_equal(plant.node_velocities(x), cws.ws.dY.reshape(-1))


@pytest.mark.parametrize("name", SCENES)
def test_the_plants_methods_give_the_numba_kernels_bits_on_shipped_scenes(name):
    rng = np.random.default_rng(len(name))
    for plant in _plants(name):
        for x, tau in _states(name, plant, rng):
            _assert_calls_match(plant, x, tau)


@pytest.mark.parametrize("space,arms", [("spatial", "contact"), ("planar", "contact"), ("planar", "full")])
def test_the_plants_methods_give_the_numba_kernels_bits_on_small_plants(space, arms):
    plant, x0 = scene(space, m=3 if space == "planar" else 2, arms=arms, damping=3.0, torsion_damping=0.2)
    rng = np.random.default_rng(3)
    for _ in range(4):
        x = x0 + rng.normal(scale=0.02, size=x0.shape)
        _assert_calls_match(plant, x, rng.normal(size=plant.input_size))


@pytest.mark.parametrize("name", ["two_panda_flip", "spatial_two_puma_carry", "planar_two_arm_lift"])
def test_the_node_state_binding_gives_the_numba_node_state_and_frames(name):
    """_core.spatial_node_state / planar_node_state (the plant's node poses, arm terms and, in space, every node's
    frames in its chart: what book_coordinates, energy and contact_wrenches read) against the numba kernels."""
    rng = np.random.default_rng(7)
    for plant in _plants(name):
        P, (_, args) = plant.plant_args, plant.kernel
        for x, _tau in _states(name, plant, rng):
            status = np.zeros(2, dtype=np.int64)
            if plant.space == "spatial":
                got = _core.spatial_node_state(x, P)
                want = numba_spatial.node_frames_state_kernel(x, *args[:8], P.node_params, status)
                names = ("Y", "dY", "J", "Jdq", "frames")
                np.testing.assert_array_equal(got["H"], numba_spatial.node_state_kernel(x, *args[:8], status)[2])
            else:
                got = _core.planar_node_state(x, P)
                want = numba_planar.node_state_kernel(x, *args[:8], status)
                names = ("Y", "dY", "H", "h", "J", "Jdq")
            assert got["status"] == tuple(status) == (0, 0)
            for name_, arr in zip(names, want):
                np.testing.assert_array_equal(got[name_], arr, err_msg=name_)


def _assert_wrenches_match(plant, Y, dY):
    P = plant.plant_args
    kern = numba_spatial if plant.space == "spatial" else numba_planar
    S_want, Fw_want, _ = kern.interconnection_kernel(Y, dY, plant.arm_count, P.edge_index, P.edge_params, P.Y_ref,
                                                     P.immobile)
    S, Fw = plant.interconnection_wrenches(Y, dY)
    np.testing.assert_array_equal(S, S_want)
    np.testing.assert_array_equal(Fw, Fw_want)
    return Fw


@pytest.mark.parametrize("name", SCENES)
def test_the_interconnection_wrenches_are_the_numba_kernels(name):
    rng = np.random.default_rng(11)
    for plant in _plants(name):
        for x, tau in _states(name, plant, rng):
            Y, dY, _ = plant.book_coordinates(x, plant.rhs(0.0, x, tau))  # the world angles, whatever the charts
            Y, dY = Y.reshape(plant.node_count, plant.p), dY.reshape(plant.node_count, plant.p)
            _assert_wrenches_match(plant, Y, dY)
            S0, _ = plant.interconnection_wrenches(Y.reshape(-1))  # flat, at rest: dY = 0
            np.testing.assert_array_equal(S0, plant.interconnection_wrenches(Y, np.zeros_like(Y))[0])


@pytest.mark.parametrize("unloaded_state", ["mobile", "immobile"])
def test_the_interconnection_wrenches_match_in_both_models_and_at_the_objects_singularity(unloaded_state):
    plant, x0 = scene("spatial", m=2, arms="contact", damping=3.0, torsion_damping=0.2, node_springs=True,
                      unloaded_state=unloaded_state)
    rng = np.random.default_rng(5)
    Y = plant.node_poses(x0).reshape(plant.node_count, 6) + rng.normal(scale=0.01, size=(plant.node_count, 6))
    dY = rng.normal(size=Y.shape)
    assert np.any(_assert_wrenches_match(plant, Y, dY))
    Y[0, 4] = np.pi / 2  # the object at pitch 90 deg: no wrench on it is defined
    np.testing.assert_array_equal(_assert_wrenches_match(plant, Y, dY), 0.0)
    with pytest.raises(ParameterError, match="Y"):
        plant.interconnection_wrenches(Y[1:])


@pytest.mark.parametrize("space", ["spatial", "planar"])
def test_the_workspaces_are_the_numba_kernels_workspaces(space):
    plant, _ = scene(space, m=3, arms="full")
    kern = numba_spatial if space == "spatial" else numba_planar
    for got, want in ((plant.workspace(), kern.make_workspace(plant.plant_args.arm_dof, plant.node_count)),
                      (plant.control_workspace(),
                       kern.make_control_workspace(plant.plant_args.arm_dof, plant.node_count))):
        assert type(got) is type(want)
        for field in got._fields:
            g, w = getattr(got, field), getattr(want, field)
            if field == "ws":
                assert type(g) is type(w)
                for f in g._fields:
                    assert getattr(g, f).shape == getattr(w, f).shape and not getattr(g, f).any(), f
            else:
                assert g.shape == w.shape and g.dtype == w.dtype and not g.any(), field


_SCRIPT = """
import gc
import sys
import numpy as np
sys.path.insert(0, sys.argv[1])
from numba.core.registry import CPUDispatcher
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
    plant.book_coordinates(x, dx), plant.interconnection_wrenches(plant.node_poses(x)), plant.workspace(), plant.control_workspace(), plant.jacobians(x, tau)
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
print([f"{o.py_func.__module__}.{o.py_func.__name__}" for o in gc.get_objects()
       if isinstance(o, CPUDispatcher) and o.signatures and o.py_func.__module__.startswith("plants")])
"""


def test_the_plants_entry_points_of_a_run_compile_no_numba_function(tmp_path):
    tests = Path(__file__).resolve().parent
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", _SCRIPT, str(tests)], env=env, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"
