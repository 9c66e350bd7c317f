"""The one builder (coopctrl/wiring.py): one function under both public names, its argument checks, and a
built loop that nothing is attached to, by the builder, a run or the failure diagnosis of ``simulate``."""

from __future__ import annotations

import pickle

import pytest

import coopctrl.simulator
import coopctrl.wiring
from coopctrl.scenario import build, load_scenario
from test_cli import REPO

def load(name, **overrides):
    return load_scenario(REPO / "scenarios" / f"{name}.toml", overrides)


def test_there_is_one_builder():
    assert coopctrl.simulator.closed_loop is coopctrl.wiring.closed_loop


def test_a_trajectory_without_evaluate_is_refused_by_name():
    scenario = load("planar_two_arm_lift")
    with pytest.raises(TypeError, match=r"trajectory = .*evaluate\(t\)"):
        coopctrl.wiring.closed_loop(scenario, trajectory=[0.0, 1.0])


@pytest.mark.parametrize("overrides, status", [
    ({"simulation.duration": 0.02}, "ok"),
    # soft grasps: the loaded start already deforms beyond the bound; the run stops at its first tick and
    # simulate diagnoses it (the closed-loop step limit, on loops of its own)
    ({"simulation.duration": 0.02, "springs[0].stiffness": 1e2, "springs[1].stiffness": 1e2}, "diverged"),
])
def test_building_and_running_attaches_nothing(overrides, status):
    scenario = load("planar_two_arm_lift", **overrides)
    before = pickle.dumps(scenario)
    loop = coopctrl.simulator.closed_loop(scenario)
    built = set(vars(loop))
    assert not hasattr(loop, "scenario")
    x0 = build.initial_state(scenario)
    given = x0.copy()
    rec = loop.run(x0, scenario.simulation.duration)
    assert rec["status"] == status
    assert (x0 == given).all()  # the start state given is unchanged
    result = coopctrl.simulator.run_result(scenario, loop)  # the run and the diagnosis of simulate
    assert result.status == status
    after = set(vars(loop))
    assert after == built  # a run attaches nothing to the loop
    assert pickle.dumps(scenario) == before  # the scenario is unchanged
