"""examples/mujoco_own_loop.py: the controller from a plain Python loop against MuJoCo stepped by hand is the
``--plant mujoco`` run (the same controller stages, the same plant, the same measurements)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import coopctrl

pytest.importorskip("mujoco")
pytestmark = pytest.mark.skipif(not hasattr(coopctrl, "Controller"), reason="needs coopctrl.Controller")

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "mujoco_own_loop.py"


def _example():
    spec = importlib.util.spec_from_file_location("mujoco_own_loop", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("name", ["planar_two_arm_lift", "two_panda_carry"])
def test_own_loop_is_the_plant_mujoco_run(name):
    from coopctrl.simulator import simulate

    duration = 0.2
    sc = coopctrl.load_scenario(name, {"simulation.duration": duration})
    t, tau, poses = _example().own_loop(sc, duration)
    run = simulate(sc, plant="mujoco", node_poses=False)
    assert run.status == "ok" and len(run.t) == len(t)
    # the same arithmetic but for the loop's record and the Controller's copies: equal to round-off growing
    # through 200 periods of a stiff plant (1e-9 of the largest torque)
    assert np.max(np.abs(tau - run.tau)) <= 1e-9 * np.max(np.abs(run.tau))
    assert np.max(np.abs(poses - run.Y0)) <= 1e-9


def test_example_prints_its_figures(capsys):
    assert _example().main(["planar_two_arm_lift", "--duration", "0.05"]) == 0
    assert "object position error RMS" in capsys.readouterr().out
