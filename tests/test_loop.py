"""The loop the user runs (issue 10): explicit loop state (repeatable runs) and the compiled tick
agreeing with the reference path (the Python tick with proxsuite at eps_abs 1e-9) on every shipped scene."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl.closed_loop import DIAGNOSIS_TICKS_BACK
from coopctrl.integrators import ImplicitEuler
from coopctrl.loop.compiled import compiled_unsupported
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
SCENES = sorted(p.stem for p in SCENARIOS.glob("*.toml"))
REFERENCE = {"load_distribution.solver": "proxsuite", "load_distribution.eps_abs": 1e-9}
COMPILED = {"load_distribution.solver": "compiled"}
ARRAYS = ("t", "x", "tau", "Y0_nominal", "F_measured", "F_commanded", "F_external", "F_internal", "r_contacts",
          "qp_iterations")


def _scene(name, **overrides):
    return coopctrl.load_scenario(SCENARIOS / f"{name}.toml", overrides)


def _same_records(a, b):
    for key in ARRAYS:
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    for key in ("status", "reason", "events", "qp_status", "qp_binding", "saturated_ticks"):
        assert a[key] == b[key], key


@pytest.mark.parametrize("solver", [COMPILED, REFERENCE], ids=["compiled", "proxsuite"])
def test_same_loop_run_twice_and_two_loops_give_bit_identical_records(solver):
    """The loop state (integrals, warm start, last split, noise position) starts afresh on every run:
    with sensor noise and quantization on, the same loop object run twice and a second loop built
    from the same scenario record the same bits."""
    noisy = {"sensors.forces.noise_std": 0.05, "sensors.joints.noise_std": 1e-5, "sensors.joints.quantization": 1e-6,
             "simulation.duration": 0.3}
    scenario = _scene("planar_two_arm_lift", **solver, **noisy)
    x0 = build.initial_state(scenario)
    loop = closed_loop(scenario)
    first = loop.run(x0, 0.3)
    second = loop.run(x0, 0.3)
    other = closed_loop(scenario).run(x0, 0.3)
    assert first["status"] == "ok" and len(first["t"]) == 301
    _same_records(first, second)
    _same_records(first, other)


@pytest.mark.parametrize("name", SCENES)
def test_compiled_tick_agrees_with_the_reference_path(name):
    """Whole run of every shipped scene: contact forces within 1e-6 N, object position within 1e-9 m.

    Both paths integrate the plant with the same arithmetic; they differ by the QP solvers'
    rounding (proxsuite at eps_abs 1e-9 against the exact active-set answer), which the closed loop
    carries along (1e-11 N on the scenes without active constraints, about 5e-7 N with torque limits
    binding; the bounds are the issue's). A run that diverges amplifies every rounding difference by
    its unstable mode (x25 per tick on euler_singularity), so there the last
    ``DIAGNOSIS_TICKS_BACK`` ticks before the stop are left out of the comparison and the stop itself
    (tick, status, diagnosis) must be the same."""
    compiled_scene = _scene(name, **COMPILED)
    assert compiled_unsupported(closed_loop(compiled_scene)) is None  # every shipped scene runs compiled
    rc = coopctrl.simulate(compiled_scene)
    rr = coopctrl.simulate(_scene(name, **REFERENCE))
    assert (rc.status, rc.reason, len(rc.t)) == (rr.status, rr.reason, len(rr.t))
    assert [e[:2] for e in rc.events] == [e[:2] for e in rr.events]
    n = len(rr.t) if rr.status == "ok" else max(1, len(rr.t) - DIAGNOSIS_TICKS_BACK)
    npos = 3 if rr.space == "spatial" else 2
    for field in ("F_measured", "F_commanded"):
        diff = np.abs(getattr(rc, field)[:n] - getattr(rr, field)[:n]).max()
        assert diff <= 1e-6, (field, diff)
    assert np.abs(rc.Y0[:n, :npos] - rr.Y0[:n, :npos]).max() <= 1e-9
    assert rc.qp_binding[:n] == rr.qp_binding[:n]


def test_noise_is_the_same_on_both_paths():
    """The noise is drawn beforehand from the scenario's seeded generators in the order the Python
    sensors draw it: with noise on every channel the compiled and reference runs still agree (as above)."""
    noisy = {"sensors.forces.noise_std": 0.05, "sensors.joints.noise_std": 1e-5, "sensors.object.noise_std": 1e-5,
             "sensors.forces.quantization": 1e-3, "simulation.duration": 0.5}
    rc = coopctrl.simulate(_scene("spatial_two_puma_carry", **COMPILED, **noisy))
    rr = coopctrl.simulate(_scene("spatial_two_puma_carry", **REFERENCE, **noisy))
    assert rc.status == rr.status == "ok"
    assert np.abs(rc.F_measured - rr.F_measured).max() <= 1e-6
    assert np.abs(rc.Y0[:, :3] - rr.Y0[:, :3]).max() <= 1e-9
    quiet = coopctrl.simulate(_scene("spatial_two_puma_carry", **COMPILED, **{"simulation.duration": 0.5}))
    assert np.abs(rc.F_measured - quiet.F_measured).max() > 1e-3  # the noise is there


@pytest.mark.parametrize("integrator", ["euler", "symplectic_euler"])
def test_compiled_integrators_agree(integrator):
    """The kernel's explicit Euler and symplectic Euler are the Python integrators' arithmetic."""
    over = {"simulation.integrator": integrator, "simulation.substeps": 4, "simulation.duration": 0.3}
    rc = coopctrl.simulate(_scene("planar_two_arm_lift", **COMPILED, **over))
    rr = coopctrl.simulate(_scene("planar_two_arm_lift", **REFERENCE, **over))
    assert rc.status == rr.status == "ok"
    assert np.abs(rc.F_measured - rr.F_measured).max() <= 1e-6
    assert np.abs(rc.Y0[:, :2] - rr.Y0[:, :2]).max() <= 1e-9


def test_unsupported_parts_name_why():
    """A loop the kernel does not implement runs the Python tick; the reason names the part."""
    class Custom(ImplicitEuler):  # a user's own scheme (the five built-in ones are compiled)
        name = "custom_scheme"

    loop = closed_loop(_scene("planar_two_arm_lift", **COMPILED), integrator=Custom())
    assert "custom_scheme" in compiled_unsupported(loop)
    assert "proxsuite" in compiled_unsupported(closed_loop(_scene("planar_two_arm_lift", **REFERENCE)))
