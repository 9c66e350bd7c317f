"""plants/core/cooperative_spatial and cooperative_energy (plants._core): the spatial cooperative plant's right-hand
side is the solve of the plant's equations with its mass matrix (the inputs' part of the accelerations,
``Gamma^-1 (tau, 0)``, against the plant's Python assembly of ``Gamma``), the right-hand side from the control terms
gives the right-hand side's bits, the control terms are the plant's node state, the arm potentials the arms' own,
and the plant energy of both spaces that of the plant's own statement of it (to rounding): on every spatial shipped
scene's plant at seeded states around its golden record (DH and URDF chain arms, contact points, offset springs,
matrix elements), on the same plants in rotation charts (arms' nodes in their own charts, the object and contact
points in stored charts) and in the immobile model, on small scenes with central springs and the book's dampers,
at an Euler singularity of the object and at coincident nodes (the statuses), and the energy on every planar
shipped scene too.

The bit-for-bit comparison with the numba kernels these replaced (plants.cooperative._spatial_kernel) went with
them: it was run when the core was ported, and the golden records (tests/golden) lock a run's numbers."""

from __future__ import annotations

import numpy as np
import pytest

import _golden
import coopctrl
from _scenes import scene
from coopctrl.scenario import build
from coopctrl.wiring import closed_loop
from plants import _core
from _plant_consistency import arm_potential, assert_inputs_act_through_the_mass_matrix
from plants.cooperative import ContactPoint
from plants.cooperative.plant_args import ARM_SERIAL_OWN_CHART
from plants.frames import rotation_zyx

SPATIAL_SCENES = ["contact_points_only", "euler_singularity", "fidelity_contact_points", "fidelity_spatial_arms",
                  "flexible_bar_carry", "spatial_three_arm_carry", "spatial_two_puma_carry", "three_iiwa_tray",
                  "two_panda_carry", "two_panda_flip", "ur5e_panda_carry"]
PLANAR_SCENES = ["planar_two_arm_lift", "fidelity_planar", "gripping_immobile_object", "central_spring_buckling",
                 "stiff_grasp_extreme", "heavy_payload_torque_limits"]
#: Spatial scenes rebuilt in the immobile model (4.5): contact points, DH arms, matrix elements, URDF arms.
IMMOBILE_SCENES = ["contact_points_only", "spatial_two_puma_carry", "flexible_bar_carry", "two_panda_carry"]
#: Small scenes (tests/_scenes.py) for what no shipped spatial scene has: central springs, the book's dampers,
#: springs between contacts, each in the mobile and the immobile model, on PUMA arms and on contact points.
SMALL_SCENES = [dict(arms=arms, element=element, unloaded_state=state, damping=4.0, torsion_damping=0.3,
                     damping_form=form, node_springs=True)
                for arms in ("full", "contact") for element in ("central", "offset")
                for state in ("mobile", "immobile") for form in ("frame_invariant", "book")]

#: The arm potentials summed in the core against the arms' own, summed in Python.
POTENTIAL_RTOL = 1e-12


def _shipped(name):
    return closed_loop(coopctrl.load_scenario(name)).plant


def _golden_starts(name):
    with np.load(_golden.path_of(name)) as record:  # the run's states: its start and a later one
        return [record["x"][0], record["x"][len(record["x"]) // 2]]


def _energy_matches(plant, x):
    """The compiled plant energy against the plant's own statement of it (CooperativePlant.kinetic_energy:
    1/2 z'^T Gamma(z) z', from the mass matrix; CooperativePlant.energy: that plus the elastic and gravitational
    potentials): the same energy summed another way, so equal to rounding (1e-10 of its size)."""
    E, T, status = _core.plant_energy(x, plant.plant_args)
    if status != 0:  # undefined there (coincident nodes): the test of that state asserts the status
        return
    assert T == pytest.approx(plant.kinetic_energy(x), rel=1e-10, abs=1e-12)
    assert E == pytest.approx(plant.energy(x), rel=1e-10, abs=1e-10 * max(1.0, abs(T)))


def _assert_spatial_kernels_consistent(plant, x, tau):
    """Every compiled spatial kernel at (x, tau), returning the right-hand side's status; where it is 0, the control
    terms' is too, the right-hand side is the mass matrix's solve, the right-hand side from the control terms gives
    its bits, the control terms are the node state, the energy and the arm potentials the plant's own."""
    P = plant.plant_args
    assert P.bases.ndim == 3
    got = np.zeros_like(x)
    status = _core.spatial_rhs(x, tau, P, got)
    if status[0] != 0:
        return status
    terms = _core.spatial_control_terms(x, P)
    assert terms["status"] == status
    from_terms = np.zeros_like(x)
    assert _core.spatial_rhs_from_terms(x, tau, P, from_terms) == status
    np.testing.assert_array_equal(from_terms, got)  # the same bits as the right-hand side itself

    def rhs(x_, tau_):
        dx = np.full_like(x_, np.nan)
        return _core.spatial_rhs(x_, tau_, P, dx)[0], dx

    assert_inputs_act_through_the_mass_matrix(plant, x, tau, rhs)
    for key, arr in zip(("Y", "dY", "H", "h", "J", "Jdq"), plant.arm_terms(x)):
        np.testing.assert_array_equal(terms[key], arr, err_msg=key)
    _energy_matches(plant, x)
    assert _core.spatial_arm_potentials(x, P) == pytest.approx(arm_potential(plant, x), rel=POTENTIAL_RTOL,
                                                               abs=POTENTIAL_RTOL)
    return status


def _trials(plant, starts, seed, count=8):
    """(x, tau): the starts as they are, then seeded states around them (positions and rates)."""
    rng = np.random.default_rng(seed)
    for trial in range(count):
        x0 = starts[trial % len(starts)]
        x = x0 + rng.normal(scale=1e-3 if trial >= len(starts) else 0.0, size=x0.shape)
        yield x, rng.normal(scale=5.0, size=plant.input_size)


def _in_charts(plant, rng):
    """The plant with every arm's node in its own chart and the object and contact points in seeded stored charts."""
    charts = np.stack([np.eye(3)] * plant.node_count)
    free = [0] + [i + 1 for i, arm in enumerate(plant.arms) if isinstance(arm, ContactPoint)]
    for k in free:
        charts[k] = rotation_zyx(rng.uniform(-1.0, 1.0, 3) * np.array([np.pi, 1.0, np.pi]))
    return plant.with_charts(charts, arm_charts="own")


@pytest.mark.parametrize("name", SPATIAL_SCENES)
def test_spatial_kernels_are_the_plants_equations(name):
    plant = _shipped(name)
    assert plant.plant_args.bases.ndim == 3, f"{name} is planar"
    starts = _golden_starts(name)
    for x, tau in _trials(plant, starts, len(name)):
        _assert_spatial_kernels_consistent(plant, x, tau)


@pytest.mark.parametrize("name", SPATIAL_SCENES)
def test_spatial_kernels_in_charts_are_the_plants_equations(name):
    plant = _shipped(name)
    why = plant.elastic.chart_dependence()
    if why is not None:
        pytest.skip(f"{name} has no charts: {why}")
    charted = _in_charts(plant, np.random.default_rng(len(name)))
    assert charted.charted and charted.plant_args.node_params.shape[1] == 14
    assert ARM_SERIAL_OWN_CHART in charted.plant_args.arm_kind or all(
        isinstance(arm, ContactPoint) for arm in plant.arms)
    for x, tau in _trials(charted, _golden_starts(name), 2 * len(name), count=4):
        _assert_spatial_kernels_consistent(charted, x, tau)


@pytest.mark.parametrize("name", IMMOBILE_SCENES)
def test_spatial_kernels_of_the_immobile_model_are_the_plants_equations(name):
    scenario = coopctrl.load_scenario(name, {"scene.unloaded_state": "immobile", "scene.rotations": "book"})
    plant = build.build_plant(scenario)
    assert plant.plant_args.immobile
    x0 = build.unloaded_state(scenario)
    x0[plant.nz:] = np.random.default_rng(1).normal(scale=0.1, size=plant.nz)
    for x, tau in _trials(plant, [x0], 3 * len(name), count=4):
        _assert_spatial_kernels_consistent(plant, x, tau)


@pytest.mark.parametrize("options", SMALL_SCENES, ids=lambda o: "-".join(str(v) for v in o.values()))
def test_spatial_kernels_of_small_scenes_are_the_plants_equations(options):
    plant, x0 = scene("spatial", 3, **options)
    rng = np.random.default_rng(7)
    x0 = x0.copy()
    x0[plant.nz:] = rng.normal(scale=0.2, size=plant.nz)
    for x, tau in _trials(plant, [x0], 11, count=4):
        _assert_spatial_kernels_consistent(plant, x, tau)


def test_an_euler_singularity_of_the_object_gives_its_status_in_every_kernel():
    for name in ("contact_points_only", "spatial_two_puma_carry"):
        plant = _shipped(name)
        x = _golden_starts(name)[0].copy()
        x[plant.nz - 2] = np.pi / 2  # the object's pitch: |cos theta| < EULER_SINGULARITY_COS
        tau = np.random.default_rng(5).normal(scale=5.0, size=plant.input_size)
        assert _core.spatial_rhs(x, tau, plant.plant_args, np.zeros_like(x)) == (1, 0)
        assert _core.spatial_control_terms(x, plant.plant_args)["status"] == (1, 0)
        assert _assert_spatial_kernels_consistent(plant, x, tau) == (1, 0)


def test_coincident_nodes_of_a_central_spring_give_their_status_in_every_kernel():
    plant, x0 = scene("spatial", 2, arms="contact", element="central", damping=4.0)
    x = x0.copy()
    x[plant.q_slice(0).start:plant.q_slice(0).start + 3] = x[plant.nz - 6:plant.nz - 3]  # contact 0 at the MC
    tau = np.random.default_rng(6).normal(scale=5.0, size=plant.input_size)
    assert _core.spatial_rhs(x, tau, plant.plant_args, np.zeros_like(x))[0] == 2  # STATUS_COINCIDENT_NODES
    assert _core.plant_energy(x, plant.plant_args)[2] == 2
    assert _assert_spatial_kernels_consistent(plant, x, tau)[0] == 2


@pytest.mark.parametrize("name", PLANAR_SCENES)
def test_the_planar_plant_energy_is_the_plants_own(name):
    plant = _shipped(name)
    P = plant.plant_args
    assert P.bases.ndim == 2
    for x, _ in _trials(plant, _golden_starts(name), len(name)):
        _energy_matches(plant, x)


def test_the_bindings_check_shapes_once():
    plant = _shipped("spatial_two_puma_carry")
    P = plant.plant_args
    x = _golden_starts("spatial_two_puma_carry")[0]
    with pytest.raises(ValueError, match="tau"):
        _core.spatial_rhs(x, np.zeros(3), P, np.zeros_like(x))
    with pytest.raises(ValueError, match="dx"):
        _core.spatial_rhs(x, np.zeros(plant.input_size), P, np.zeros(3))
    with pytest.raises(ValueError, match="P.bases"):
        _core.spatial_control_terms(x, _shipped("planar_two_arm_lift").plant_args)
