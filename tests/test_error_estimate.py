"""The error bar of a run (issue 19 item 3): ``coopctrl run --estimate-error``
(coopctrl.analysis.error_estimate): a rerun at half the step, or at tolerances 100 times smaller."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl import cli
from coopctrl.analysis.error_estimate import estimate_error
from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator
from coopctrl.analysis.tradeoff import make_integrator, run_errors, run_loop
from coopctrl.scenario import build

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"


def load(name, **overrides):
    return coopctrl.load_scenario(SCENARIOS / f"{name}.toml", overrides or None)


@pytest.mark.parametrize("integrator, substeps", [("euler", 1), ("implicit_midpoint", 1)])
def test_estimated_error_is_within_a_factor_10_of_the_true_error(integrator, substeps):
    """planar_two_arm_lift for 0.4 s: the Richardson estimate (a rerun at h/2) against the error measured
    against the reference. Asymptotically it is exact to O(h) relative terms (measured within 20 %); the
    factor 10 the issue allows covers the closed loop's feedback (the maximum over the run of the
    difference is not the difference of the maxima) and the force error near its rounding floor."""
    scene = load("planar_two_arm_lift", **{"simulation.duration": 0.4, "simulation.integrator": integrator,
                                           "simulation.substeps": substeps})
    estimate = estimate_error(scene)
    x0 = build.initial_state(scene)
    ref = run_loop(scene, x0, ReferenceIntegrator(ReferenceConfig()), 1, None)
    true = run_errors(run_loop(scene, x0, make_integrator(integrator), substeps, None), ref)
    for got, want in ((estimate.position_m, true["position_error_m"]),
                      (estimate.orientation_rad, true["orientation_error_rad"]),
                      (estimate.force_N, true["force_error_N"])):
        assert np.isfinite(got) and want / 10 <= got <= want * 10, (integrator, got, want)


def test_run_estimate_error_keys(capsys):
    code = cli.main(["run", "planar_two_arm_lift", "--set", "simulation.duration=0.1", "--set",
                     "simulation.substeps=2", "--estimate-error", "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    summary = json.loads(captured.out)
    for key in ("estimated_position_error_m", "estimated_orientation_error_rad", "estimated_force_error_N"):
        assert summary[key] is not None and np.isfinite(summary[key]) and summary[key] > 0
    assert "T/4" in summary["error_estimate_tighter_setting"] and summary["error_estimate_reason"] == ""


def test_no_estimate_when_the_tighter_tolerance_takes_the_same_steps():
    """rk45 at rtol 1e-4 and 1e-6 both cross each 1 ms period of planar_two_arm_lift in one step (the
    period, not the tolerance, limits it): a difference of 0 would be no estimate, and it says so."""
    scene = load("planar_two_arm_lift", **{"simulation.duration": 0.05, "simulation.integrator": "rk45",
                                           "simulation.rtol": 1e-4})
    estimate = estimate_error(scene)
    assert estimate.position_m is None and "same steps" in estimate.reason
    assert "rtol 1e-06" in estimate.tighter_setting
