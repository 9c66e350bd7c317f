"""plants/core/cooperative_planar (plants._core): the planar cooperative plant's right-hand side is the solve of the
plant's equations with its mass matrix (the inputs' part of the accelerations, ``Gamma^-1 (tau, 0)``), its control
terms are the plant's node state and its arm potentials the arms' own, on every planar shipped scene's plant at
seeded states around its start (serial arms and contact points, mobile and immobile objects, springs, dampers and
matrix elements).

The bit-for-bit comparison with the numba kernels these replaced (plants.cooperative._planar_kernel) went with
them: it was run when the core was ported, and the golden records (tests/golden) lock a run's numbers."""

from __future__ import annotations

import numpy as np
import pytest

import _golden
import coopctrl
from _plant_consistency import arm_potential, assert_inputs_act_through_the_mass_matrix
from coopctrl.wiring import closed_loop
from plants import _core

PLANAR_SCENES = ["planar_two_arm_lift", "fidelity_planar", "gripping_immobile_object", "central_spring_buckling",
                 "stiff_grasp_extreme", "heavy_payload_torque_limits", "fidelity_contact_points"]
#: The arm potentials summed in the core against the arms' own, summed in Python.
POTENTIAL_RTOL = 1e-12


def _planar_plant(name):
    loop = closed_loop(coopctrl.load_scenario(name))
    plant = loop.plant
    if plant.plant_args.bases.ndim != 2:
        pytest.skip(f"{name} is spatial")
    return plant, loop


def _rhs(P):
    def rhs(x, tau):
        dx = np.full_like(x, np.nan)
        return _core.planar_rhs(x, tau, P, dx)[0], dx
    return rhs


@pytest.mark.parametrize("name", PLANAR_SCENES)
def test_planar_rhs_control_terms_and_potentials_are_the_plants_equations(name):
    plant, loop = _planar_plant(name)
    P = plant.plant_args
    with np.load(_golden.path_of(name)) as record:  # the run's states: its start and a later one
        starts = [record["x"][0], record["x"][len(record["x"]) // 2]]
    rng = np.random.default_rng(len(name))
    for trial in range(10):
        x0 = starts[trial % 2]
        x = x0 + rng.normal(scale=1e-3 if trial > 1 else 0.0, size=x0.shape)
        tau = rng.normal(scale=5.0, size=plant.input_size)
        assert_inputs_act_through_the_mass_matrix(plant, x, tau, _rhs(P))
        terms = _core.planar_control_terms(x, P)
        assert terms["status"] == (0, 0)
        for key, arr in zip(("Y", "dY", "H", "h", "J", "Jdq"), plant.arm_terms(x)):
            np.testing.assert_array_equal(terms[key], arr, err_msg=key)
        assert _core.planar_arm_potentials(x, P) == pytest.approx(arm_potential(plant, x), rel=POTENTIAL_RTOL,
                                                                  abs=POTENTIAL_RTOL)
