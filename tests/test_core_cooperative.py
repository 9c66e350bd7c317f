"""plants/core/cooperative_planar (plants._core): the planar cooperative plant's right-hand side, control terms and
arm potentials give the numbers of the numba kernels the loop runs today (plants.cooperative._planar_kernel), bit
for bit, on every planar shipped scene's plant at seeded states around its start (serial arms and contact points,
mobile and immobile objects, springs, dampers and matrix elements)."""

from __future__ import annotations

import numpy as np
import pytest

import _golden
import coopctrl
from coopctrl.wiring import closed_loop
from plants import _core
from plants.cooperative import _planar_kernel as numba_planar

PLANAR_SCENES = ["planar_two_arm_lift", "fidelity_planar", "gripping_immobile_object", "central_spring_buckling",
                 "stiff_grasp_extreme", "heavy_payload_torque_limits", "fidelity_contact_points"]


def _planar_plant(name):
    loop = closed_loop(coopctrl.load_scenario(name))
    plant = loop.plant
    if plant.plant_args.bases.ndim != 2:
        pytest.skip(f"{name} is spatial")
    return plant, loop


@pytest.mark.parametrize("name", PLANAR_SCENES)
def test_planar_rhs_and_control_terms_match_the_numba_kernels_bit_for_bit(name):
    plant, loop = _planar_plant(name)
    P = plant.plant_args
    with np.load(_golden.path_of(name)) as record:  # the run's states: its start and a later one
        starts = [record["x"][0], record["x"][len(record["x"]) // 2]]
    rng = np.random.default_rng(len(name))
    ws = plant.workspace()
    cws = plant.control_workspace()
    for trial in range(10):
        x0 = starts[trial % 2]
        x = x0 + rng.normal(scale=1e-3 if trial > 1 else 0.0, size=x0.shape)
        tau = rng.normal(scale=5.0, size=plant.input_size)
        want, got = np.empty_like(x), np.empty_like(x)
        st_want = np.zeros(2, np.int64)
        numba_planar.rhs_into_packed(x, tau, P, st_want, ws, want)
        st_got = _core.planar_rhs(x, tau, P, got)
        assert st_got == tuple(st_want)
        np.testing.assert_array_equal(got, want)
        numba_planar.control_terms_packed(x, P, st_want, cws)
        terms = _core.planar_control_terms(x, P)
        n = terms["H"].shape[1]
        for key, ref in (("Y", cws.ws.Y), ("dY", cws.ws.dY), ("H", cws.ws.H), ("h", cws.ws.h), ("J", cws.ws.J),
                         ("Jdq", cws.ws.Jdq), ("W", cws.W), ("w_free", cws.w_free), ("S", cws.S), ("Fw", cws.Fw)):
            np.testing.assert_array_equal(terms[key], ref[..., :n, :n] if key == "H" else ref, err_msg=key)
        assert _core.planar_arm_potentials(x, P) == numba_planar.arm_potential_kernel(
            x, P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases, P.gravity)
