"""The loop state (coopctrl/loop/state.py): a run ends with the state it reached (``record.final_state``),
and ``loop.run(final_state, duration)`` continues from it. The two records, one after the other, are the
record of one long run bit for bit: every integrator family, sensor noise and quantization, a run in
rotation charts that re-centres before and after the split, an integrator stepped in Python. A run
changes nothing it was given, so the same state can be continued twice."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
ARRAYS = ("t", "x", "tau", "Y0_nominal", "F_measured", "F_commanded", "F_external", "F_internal", "r_contacts",
          "squeeze", "qp_iterations", "qp_active_rows")
NOISY = {"sensors.joints.noise_std": 1e-4, "sensors.joints.quantization": 1e-6, "sensors.forces.noise_std": 0.5,
         "sensors.object.noise_std": 1e-4}


def _scene(name, **overrides):
    return coopctrl.load_scenario(SCENARIOS / f"{name}.toml", overrides or None)


def _joined(first, second, key):
    return np.concatenate([np.asarray(first[key]), np.asarray(second[key])])


def _assert_continues(loop, x0, first_s: float, second_s: float):
    """``loop.run(x0, first_s)`` then ``loop.run(final_state, second_s)`` against one run of the sum."""
    whole = loop.run(x0, first_s + second_s)
    first = loop.run(x0, first_s)
    second = loop.run(first["final_state"], second_s)
    assert whole["status"] == first["status"] == second["status"] == "ok", (first["reason"], second["reason"])
    assert len(first["t"]) + len(second["t"]) == len(whole["t"])
    for key in ARRAYS:
        np.testing.assert_array_equal(_joined(first, second, key), whole[key], err_msg=key)
    assert first["qp_status"] + second["qp_status"] == whole["qp_status"]
    if whole.get("integration_steps") is not None:
        # the statistics of the last tick of the first run count the period it did not advance
        np.testing.assert_array_equal(second["integration_steps"], whole["integration_steps"][len(first["t"]):])
    return first, second, whole


@pytest.mark.parametrize("name, overrides, first_s, second_s", [
    ("spatial_two_puma_carry", {}, 0.3, 0.2),
    ("planar_two_arm_lift", NOISY, 0.2, 0.25),
    ("planar_two_arm_lift", {"simulation.integrator": "implicit_midpoint"}, 0.15, 0.15),
    ("planar_two_arm_lift", {"simulation.integrator": "rk45"}, 0.15, 0.15),
    ("planar_two_arm_lift", {"simulation.integrator": "trbdf2"}, 0.15, 0.15),
], ids=["spatial-rk4", "planar-noisy", "implicit-midpoint", "rk45", "trbdf2"])
def test_a_run_continued_from_its_final_state_is_one_long_run(name, overrides, first_s, second_s):
    """Continuing carries the state, the held torques, the integrals, the QP's warm start, the integrator's
    step-to-step state (Newton matrix, step size) and the noise streams' position: bit for bit."""
    scenario = _scene(name, **overrides)
    loop = closed_loop(scenario)
    _assert_continues(loop, build.initial_state(scenario, loop), first_s, second_s)


@pytest.mark.parametrize("first_s", [0.9, 1.2], ids=["split-before-a-recentring", "split-between-recentrings"])
def test_a_run_in_rotation_charts_continues_in_the_chart_it_ended_in(first_s):
    """The flip re-centres its world chart at 45.6 and 91 deg of pitch: split before the first re-centring and
    between the two, the continuation resumes in the chart (and at the chart check) where the first run ended,
    so its record, turned back into the book's world, is the long run's."""
    scenario = _scene("two_panda_flip")
    loop = closed_loop(scenario)
    first, second, whole = _assert_continues(loop, build.initial_state(scenario, loop), first_s, 2.0 - first_s)
    recentred = [[e[0] for e in r["events"] if e[1] == "chart_recentred"] for r in (first, second, whole)]
    assert len(recentred[2]) == 2 and recentred[0] + recentred[1] == recentred[2]
    np.testing.assert_array_equal(_joined(first, second, "object_rotation"), whole["object_rotation"])


def test_an_integrator_stepped_in_python_continues_too():
    """The reference integrator (scipy's DOP853, between kernel calls) steps the period the first run did not."""
    from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator

    scenario = _scene("planar_two_arm_lift")
    loop = closed_loop(scenario, integrator=ReferenceIntegrator(ReferenceConfig()))
    _assert_continues(loop, build.initial_state(scenario, loop), 0.1, 0.1)


def test_on_the_reference_path_a_continuation_agrees_to_the_solvers_tolerance():
    """The reference path's QP backend (proxsuite here) is not part of the loop state: the continuation starts
    it cold. Its answers then differ from the warm-started ones within the solve tolerance (eps_abs = 1e-9 N),
    and the stable loop does not amplify that (measured: 3e-12 N, 1e-13 m)."""
    scenario = _scene("planar_two_arm_lift", **{"load_distribution.solver": "proxsuite",
                                                "load_distribution.eps_abs": 1e-9})
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    whole, first = loop.run(x0, 0.4), loop.run(x0, 0.2)
    second = loop.run(first["final_state"], 0.2)
    assert second["status"] == "ok"
    np.testing.assert_array_equal(first["x"], whole["x"][:len(first["t"])])
    np.testing.assert_allclose(_joined(first, second, "F_commanded"), whole["F_commanded"], rtol=0, atol=1e-7)
    np.testing.assert_allclose(_joined(first, second, "x"), whole["x"], rtol=0, atol=1e-9)


def test_a_run_changes_nothing_it_was_given_and_a_state_continues_twice_alike():
    """The start state, the integrals mapping and the final state given to a continuation are unchanged after
    the runs; continuing the same final state twice gives the same record."""
    scenario = _scene("planar_two_arm_lift", **NOISY)
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    x0_before = x0.copy()
    follower = next(iter(loop.followers))
    integrals = {follower: np.full(loop.plant.p, 0.01)}
    first = loop.run(x0, 0.1, integrals=integrals)
    np.testing.assert_array_equal(x0, x0_before)
    np.testing.assert_array_equal(integrals[follower], np.full(loop.plant.p, 0.01))
    state = first["final_state"]
    before = state.copy()
    again = [loop.run(state, 0.1) for _ in range(2)]
    for name in ("x", "tau", "integrals", "last_split", "flags", "saturated_joints", "hold"):
        np.testing.assert_array_equal(getattr(state, name), getattr(before, name), err_msg=name)
    assert state.tick == before.tick == len(first["t"])
    for key in ARRAYS:
        np.testing.assert_array_equal(again[0][key], again[1][key], err_msg=key)


def test_a_continuation_of_no_time_advances_the_pending_period_only():
    """``duration = 0`` records nothing; its final state is the next tick's, so continuing from it is the same
    as continuing from the state it was given."""
    scenario = _scene("planar_two_arm_lift")
    loop = closed_loop(scenario)
    first = loop.run(build.initial_state(scenario, loop), 0.1)
    empty = loop.run(first["final_state"], 0.0)
    assert empty["status"] == "ok" and len(empty["t"]) == 0
    direct = loop.run(first["final_state"], 0.1)
    through = loop.run(empty["final_state"], 0.1)
    for key in ARRAYS:
        np.testing.assert_array_equal(through[key], direct[key], err_msg=key)


def test_what_cannot_be_continued_is_refused_naming_it():
    """A failed run's final state, a state of another loop, integrals given with a state: one line naming ``x0``
    or ``integrals`` and what is allowed."""
    scenario = _scene("planar_two_arm_lift")
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    ok = loop.run(x0, 0.05)["final_state"]
    with pytest.raises(ValueError, match=r"integrals = .* expected None when x0 is a LoopState"):
        loop.run(ok, 0.05, integrals={next(iter(loop.followers)): np.zeros(loop.plant.p)})
    spatial = closed_loop(_scene("spatial_two_puma_carry"))
    with pytest.raises(ValueError, match=r"x0 = .* expected a plant state of size .* its sizes are another loop's"):
        spatial.run(ok, 0.05)
    failing = _scene("central_spring_buckling")  # statically unstable: diverges within 0.1 s
    bad_loop = closed_loop(failing)
    failed = bad_loop.run(build.initial_state(failing, bad_loop), failing.simulation.duration)
    assert failed["status"] != "ok"
    with pytest.raises(ValueError, match=r"x0 = .* that ended ok: this run stopped early"):
        bad_loop.run(failed["final_state"], 0.05)
