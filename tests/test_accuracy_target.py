"""The accuracy target (issue 19 items 2 and 3): ``coopctrl tradeoff --target``, ``simulation.accuracy``
(coopctrl.analysis.accuracy_target; ``--estimate-error``: tests/test_error_estimate.py).

Scenes are shortened (0.4 to 0.6 s: longer than the 0.25 s prefix, so that the growth after the prefix
is part of what is checked); costs are compared in right-hand-side evaluations (exact counts), never in
wall time. The full check over the shipped scenes at their whole durations is
benchmarks/bench_accuracy_target.py.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl import cli
from coopctrl.analysis import accuracy_target as at
from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator
from coopctrl.analysis.tradeoff import is_adaptive, make_integrator, run_errors, run_loop
from coopctrl.cli import tradeoff as tradeoff_cli
from coopctrl.errors import ScenarioError
from coopctrl.scenario import build
from coopctrl.scenario.simulation import SimulationConfig

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
TARGETS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7)


def load(name, **overrides):
    return coopctrl.load_scenario(SCENARIOS / f"{name}.toml", overrides or None)


def test_prefix_rule():
    """min(duration, max(0.25 s, 50 T)) in whole periods."""
    assert at.prefix_duration(SimulationConfig(duration=2.5, control_period=1e-3)) == pytest.approx(0.25)
    assert at.prefix_duration(SimulationConfig(duration=2.5, control_period=0.01)) == pytest.approx(0.5)
    assert at.prefix_duration(SimulationConfig(duration=0.1, control_period=1e-3)) == pytest.approx(0.1)
    assert at.prefix_duration(SimulationConfig(duration=1.0, control_period=3e-3)) == pytest.approx(84 * 3e-3)


def test_cli_ranges_agree_with_the_module():
    assert tradeoff_cli.TARGET_RANGE_M == at.TARGET_RANGE_M
    assert tradeoff_cli.FORCE_TARGET_RANGE_N == at.FORCE_TARGET_RANGE_N


@pytest.mark.parametrize("bad", [0.0, -1e-6, float("nan"), float("inf"), 2.0, 1e-20, "1e-6", True, None])
def test_bad_target_raises_naming_it(bad):
    with pytest.raises(ScenarioError, match="target"):
        at.check_target(bad)


# ---------------------------------------------------------------------- meets the target, at what cost
#: (scene, shortened duration [s]): one planar, one spatial; both fast. The spatial one runs 0.4 s.
CASES = (("planar_two_arm_lift", 0.6), ("contact_points_only", 0.4))


def _full_grid(scene, x0, ref):
    """Full-run error and rhs evaluations of every fixed-step candidate: {(name, n): (error, rhs)}."""
    out = {}
    for name in at.parse_integrators(None):
        if is_adaptive(name):
            continue
        for n, _ in at.candidates(name):
            run = run_loop(scene, x0, make_integrator(name), n, None)
            err = run_errors(run, ref)["position_error_m"] if run.status == "ok" else np.inf
            out[name, n] = (err, run.rhs_evaluations)
            if err <= min(TARGETS):
                break  # finer steps of this scheme cost more and are not needed by any target
    return out


@pytest.mark.parametrize("name, duration", CASES)
def test_recommendation_meets_the_target_over_the_whole_run_at_a_bounded_cost(name, duration):
    """Issue 19: for targets 1e-3 to 1e-7 m, the recommended setting meets the target over the whole
    run (not only the prefix), and costs at most 1.5 times the cheapest fixed-step setting of the full
    grid that meets it over the whole run (1.5: the largest ratio of neighbouring candidates but the
    first, 1 -> 2 substeps; counted in rhs evaluations). Every case here must hit (the issue asks 95 %
    over the shipped scenes: the benchmark's figure)."""
    scene = load(name, **{"simulation.duration": duration})
    x0 = build.initial_state(scene)
    ref = run_loop(scene, x0, ReferenceIntegrator(ReferenceConfig()), 1, None)
    grid = _full_grid(scene, x0, ref)
    for target in TARGETS:
        search = at.recommend(scene, target)
        rec = search.recommendation
        assert rec is not None, (name, target, search.text())
        row = rec.row
        run = run_loop(scene, x0, make_integrator(row.integrator, row.rtol), row.substeps or 1, None)
        full = run_errors(run, ref)["position_error_m"]
        assert full <= target, (name, target, at.describe(row), full)
        fixed = [rhs for err, rhs in grid.values() if err <= target]
        if fixed:
            assert run.rhs_evaluations <= 1.5 * min(fixed), (name, target, at.describe(row), run.rhs_evaluations,
                                                              min(fixed))


# ---------------------------------------------------------------------- the command line
def test_tradeoff_target_json_document(capsys):
    """The JSON names fixed by the issue; the "set" values, given to --set, select the setting."""
    code = cli.main(["tradeoff", "planar_two_arm_lift", "--set", "simulation.duration=0.3", "--target", "1e-5",
                     "--json"])
    out = capsys.readouterr().out
    assert code == 0
    data = json.loads(out)
    assert {"rows", "recommendation", "target_m", "prefix_s", "safety_factor"} <= set(data)
    assert data["rows"] and all("integrator" in r for r in data["rows"])
    rec = data["recommendation"]
    assert {"set", "error_m", "wall_time_s"} <= set(rec)
    assert rec["error_m"] * data["safety_factor"] <= 1e-5 and rec["wall_time_s"] > 0
    assert "simulation.integrator" in rec["set"]
    chosen = coopctrl.load_scenario(SCENARIOS / "planar_two_arm_lift.toml",
                                    {k: str(v) for k, v in rec["set"].items()}).simulation
    assert chosen.integrator == rec["set"]["simulation.integrator"]
    if "simulation.substeps" in rec["set"]:
        assert chosen.substeps == rec["set"]["simulation.substeps"]
    else:
        assert chosen.rtol == rec["set"]["simulation.rtol"] and chosen.atol == rec["set"]["simulation.atol"]


def test_tradeoff_target_text_prints_set_lines(capsys):
    code = cli.main(["tradeoff", "planar_two_arm_lift", "--set", "simulation.duration=0.3", "--target", "1e-3",
                     "--integrators", "rk4"])
    out = capsys.readouterr().out
    assert code == 0
    assert "--set simulation.integrator=rk4" in out and "--set simulation.substeps=1" in out and "rhs evaluations" in out


def test_unreachable_target_exits_1_with_the_best_error(capsys):
    """Euler cannot reach 1e-11 m within 128 substeps (its error is ~1e-8 m there)."""
    code = cli.main(["tradeoff", "planar_two_arm_lift", "--set", "simulation.duration=0.1", "--target", "1e-11",
                     "--integrators", "euler"])
    err = capsys.readouterr().err
    assert code == 1
    assert len(err.strip().splitlines()) == 1
    assert "no setting meets the target 1e-11 m" in err and "best error reached" in err and "rhs evaluations" in err


@pytest.mark.parametrize("value", ["0", "-1e-6", "nan", "inf", "2", "1e-30", "abc"])
def test_bad_target_exits_2_with_one_line(capsys, value):
    code = cli.main(["tradeoff", "planar_two_arm_lift", f"--target={value}"])
    err = capsys.readouterr().err
    assert code == 2
    assert len(err.strip().splitlines()) == 1 and "--target" in err and repr(value) in err


def test_force_target_needs_target(capsys):
    code = cli.main(["tradeoff", "planar_two_arm_lift", "--force-target", "1e-3"])
    assert code == 2 and "--force-target needs --target" in capsys.readouterr().err


def test_force_target_is_met_on_the_prefix():
    scene = load("planar_two_arm_lift", **{"simulation.duration": 0.3})
    search = at.recommend(scene, 1e-3, force_target_N=1e-4, integrators=["rk4", "euler"])
    rec = search.recommendation
    assert rec is not None and rec.row.force_error_N * search.safety_factor <= 1e-4
    assert rec.prediction["predicted_force_error_N"] * search.safety_factor <= 1e-4


def test_run_with_accuracy_applies_the_choice(capsys):
    code = cli.main(["run", "planar_two_arm_lift", "--set", "simulation.duration=0.3",
                     "--set", "simulation.accuracy=1e-5", "--json"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    summary = json.loads(captured.out)
    choice = summary["accuracy_choice"]
    assert summary["integrator"] == choice["set"]["simulation.integrator"]
    assert choice["error_m"] * choice["safety_factor"] <= 1e-5
    assert "simulation.accuracy = 1e-05 m: chose" in captured.err


@pytest.mark.parametrize("bad", ["0", "-1", "nan", "2"])
def test_run_bad_accuracy_exits_2(capsys, bad):
    code = cli.main(["run", "planar_two_arm_lift", "--set", f"simulation.accuracy={bad}"])
    err = capsys.readouterr().err
    assert code == 2 and "simulation.accuracy" in err and len(err.strip().splitlines()) == 1
