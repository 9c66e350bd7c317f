"""The loop's failure diagnosis (coopctrl/loop/diagnosis.py) and its Euler-angle band (coopctrl/loop/euler_band.py):
each stop classified from the evidence, and a loop wired without the analysis layer's failure causes still
names its failure and judges the step by the open-loop prediction."""

from __future__ import annotations

import math

import numpy as np
import pytest

import coopctrl.analysis.euler_singularity as public_band
from coopctrl import wiring
from coopctrl.errors import DivergenceError, InfeasibleLoad
from coopctrl.loop import diagnosis, euler_band
from coopctrl.scenario import build, load_scenario
from coopctrl.simulator import closed_loop
from plants.errors import EulerSingularityError
from test_cli import REPO


def load(name, **overrides):
    return load_scenario(REPO / "scenarios" / f"{name}.toml", overrides)


def test_the_analysis_layer_keeps_the_band_names():
    for name in public_band.__all__:
        assert getattr(public_band, name) is getattr(euler_band, name)


@pytest.mark.parametrize("where,node", [("contact node 2 (arms[1])", 2), ("object", 0), ("", 0)])
def test_a_plant_singularity_names_its_node(where, node):
    hit = euler_band.hit_from_plant_error(EulerSingularityError(where, 0.5 * math.pi - 1e-7, 1e-7), 0.25)
    assert (hit.node, hit.time) == (node, 0.25)
    assert hit.cos_theta == pytest.approx(1e-7, rel=1e-6)  # |cos| of the pitch given


def _evidence(loop, x0, k_done=3):
    rec = {"x": np.tile(x0, (k_done, 1)), "t": np.arange(k_done) * loop.T}
    saturation = {"saturated_ticks": 0, "saturated_joint_ticks": np.zeros(loop.plant.input_size, dtype=int),
                  "saturation_first_time_s": math.nan, "saturated_last_tick": -1}
    return rec, saturation


def test_each_stop_is_classified():
    scenario = load("spatial_two_puma_carry")
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    rec, sat = _evidence(loop, x0)
    hit = euler_band.SingularityHit(1, math.radians(86.0), math.cos(math.radians(86.0)), 0.002)
    events = []
    status, reason = diagnosis.stop_reason(loop, euler_band.NearSingularity(hit), 2, 3, rec, x0, x0, 0.002, x0,
                                           events, sat)
    assert status == "diverged" and reason.startswith("Euler-angle singularity at t = 0.002 s")
    assert "a smaller step does not help" in reason and events[-1][1] == "euler_singularity"
    events = [(0.001, "qp_held", "QP status 'infeasible' (binding: min_grip); holding the last feasible split")]
    status, reason = diagnosis.stop_reason(loop, InfeasibleLoad("infeasible", ("min_grip",), "no split"), 2, 3, rec,
                                           x0, x0, 0.002, x0, events, sat)
    assert status == "qp_failed" and "cause: load distribution: the QP failed on 1 ticks" in reason
    assert events[-1][1] == "qp_failed"
    with pytest.raises(TypeError, match="not a stop of the loop"):
        diagnosis.stop_reason(loop, KeyError("x"), 2, 3, rec, x0, x0, 0.002, x0, [], sat)


def test_a_divergence_names_the_quantity_and_judges_the_step():
    """A deformation guard at tick 2 of the carry (RK4 at 1 ms, well inside every limit): the quantity and
    time are named and the step is not blamed, with and without the analysis layer's causes."""
    scenario = load("spatial_two_puma_carry")
    x0 = build.initial_state(scenario)
    for loop in (closed_loop(scenario), wiring.closed_loop(scenario)):
        loop.run(x0, 0.0)  # the open-loop step limit is predicted about the state the last run started from
        rec, sat = _evidence(loop, x0)
        events = []
        status, reason = diagnosis.stop_reason(loop, DivergenceError(0.002, "deformation of contact 0 [m]", 0.5), 2, 3,
                                               rec, x0, x0, 0.001, x0, events, sat)
        assert status == "diverged" and "deformation of contact 0" in reason
        assert "not the likely cause" in reason and "try a step" not in reason
        assert events[-1][1] == "diverged"


def test_without_the_failure_analysis_the_static_instability_is_still_named():
    """``wiring.closed_loop`` wires no ``failure_causes``: the loop's own (open-loop) diagnosis names the
    buckling grasp, as the full one does."""
    scenario = load("central_spring_buckling", **{"simulation.duration": 0.1})
    loop = wiring.closed_loop(scenario)
    assert loop.failure_causes is None
    rec = loop.run(build.initial_state(scenario), 0.1)
    assert rec["status"] == "diverged"
    assert "statically unstable" in rec["reason"] and "try a step" not in rec["reason"]


def test_a_stop_records_its_facts_for_a_diagnosis_after_the_run():
    """The run's stop carries its raw facts (``rec["stop"]``): the same facts give the loop's reason again,
    and causes found after the run (simulate's, with the scenario) replace the loop's own."""
    scenario = load("planar_two_arm_lift")
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    loop.run(x0, 0.0)  # the open-loop step limit is predicted about the state the last run started from
    rec, sat = _evidence(loop, x0)
    events = []
    status, reason = diagnosis.stop_reason(loop, DivergenceError(0.002, "deformation of contact 0 [m]", 0.5), 2, 3,
                                           rec, x0, x0, 0.001, x0, events, sat)
    stop = rec["stop"]
    assert status == stop.status == "diverged" and stop.causes_decide and (stop.tick, stop.ticks_done) == (2, 3)
    assert events[stop.event][2] == reason
    assert diagnosis.rediagnose(loop, stop, diagnosis.open_loop_causes) == reason

    def later(*evidence):
        return diagnosis.Diagnosis(("a cause found after the run",), False, math.inf)

    again = diagnosis.rediagnose(loop, stop, later)
    assert "deformation of contact 0" in again
    assert again.endswith("cause: a cause found after the run") and "closed loop's stable range" in again
    # a QP failure's reason does not depend on the divergence's causes: nothing to diagnose again
    diagnosis.stop_reason(loop, InfeasibleLoad("infeasible", ("min_grip",), "no split"), 2, 3, rec, x0, x0, 0.002,
                          x0, [], sat)
    assert rec["stop"].status == "qp_failed" and diagnosis.rediagnose(loop, rec["stop"], later) is None
