"""Every run ends (issue 45 item 2; coopctrl.loop.step_budget): an error-controlled run beyond its step budget
ends with exit 1 and one line naming the scheme, the steps and the budget. The budgets are patched small here
so that a shipped scene meets them in a few ticks (the defaults are met only by an unreachable tolerance)."""

from __future__ import annotations

import numpy as np

from coopctrl import cli
import coopctrl.loop.step_budget as SB
from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator
from coopctrl.analysis.tradeoff import run_loop
from coopctrl.scenario import build, load_scenario


def run_cli(args, capsys):
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_budget_is_the_rate_times_the_periods():
    assert SB.step_budget(0, 7) == 7 and SB.step_budget(10, 7) == 70


def test_compiled_scheme_beyond_its_budget_ends_through_the_cli(capsys, monkeypatch):
    """rk45 on stiff_grasp_extreme (1e7 N/m grasps: its explicit step is limited below the 1 ms period) takes
    about 2 steps per period (100 in its first 50): with a budget of 1 per period the run ends at its first
    check with exit 1, naming rk45 and the budget."""
    monkeypatch.setattr(SB, "STEPS_PER_PERIOD", 1)
    code, out, err = run_cli(["run", "stiff_grasp_extreme", "-q", "--no-preflight", "--set",
                              "simulation.integrator='rk45'", "--set", "simulation.duration=0.05"], capsys)
    assert code == 1, err
    line = err.strip().splitlines()[-1]
    assert line.startswith("coopctrl: diverged: ") and "rk45 took" in line and "beyond its budget of" in line
    assert "Traceback" not in err


def test_python_reference_beyond_its_budget_ends():
    """The DOP853 reference (stepped in Python) on stiff_grasp_extreme, several steps per period, with a budget
    of 1 step per period: it ends at once, naming the budget."""
    from pathlib import Path

    scene = load_scenario(Path(__file__).resolve().parent.parent / "scenarios" / "stiff_grasp_extreme.toml",
                          {"simulation.duration": 0.01})
    saved = SB.PYTHON_STEPS_PER_PERIOD
    SB.PYTHON_STEPS_PER_PERIOD = 1
    try:
        run = run_loop(scene, build.initial_state(scene), ReferenceIntegrator(ReferenceConfig()), 1, 0.01)
    finally:
        SB.PYTHON_STEPS_PER_PERIOD = saved
    assert run.status == "diverged" and "reference took" in run.reason and "budget" in run.reason


def test_fuzz_every_run_ends(capsys, monkeypatch):
    """Seeded: error-controlled runs at random schemes, tolerances and stiffnesses within the reference's
    ranges, with a budget of 50 steps per period: each ends with exit 0 (within it) or 1 (its one line names
    the budget or another cause), never a hang or a traceback."""
    monkeypatch.setattr(SB, "STEPS_PER_PERIOD", 50)
    rng = np.random.default_rng(452)
    for _ in range(3):
        scheme = str(rng.choice(["rk23", "rk45"]))
        rtol = 10 ** rng.uniform(-12, -3)
        k = 10 ** rng.uniform(3, 8)
        code, out, err = run_cli(["run", "-q", "--no-preflight", "--set", f"simulation.integrator='{scheme}'",
                                  "--set", f"simulation.rtol={rtol!r}", "--set", f"springs[0].stiffness={k!r}",
                                  "--set", f"springs[1].stiffness={k!r}", "--set", "simulation.duration=0.05"],
                                 capsys)
        assert code in (0, 1), err
        assert "Traceback" not in err and "internal error" not in err
        if code == 1:
            assert err.strip().splitlines()[-1].startswith("coopctrl: "), err


def test_long_run_is_announced(monkeypatch):
    """An error-controlled run whose stable step implies more than LONG_RUN_STEPS steps says so first: rk45 on
    stiff_grasp_extreme (about 2 steps per 1 ms period) over 1 s, with the threshold at 10 steps; rk4 (fixed
    step) never."""
    from pathlib import Path

    from coopctrl.simulator import closed_loop

    path = Path(__file__).resolve().parent.parent / "scenarios" / "stiff_grasp_extreme.toml"
    monkeypatch.setattr(SB, "LONG_RUN_STEPS", 10)
    for scheme, said in (("rk45", True), ("rk4", False)):
        scene = load_scenario(path, {"simulation.integrator": scheme})
        loop = closed_loop(scene)
        line = SB.long_run_notice(loop, build.initial_state(scene, loop), 1.0)
        assert bool(line) == said and (not said or ("rk45 will take at least" in line and "budget" in line))


def test_unreachable_accuracy_target_ends(capsys):
    """The issue's case: simulation.accuracy = 1e-3 m with 1e10 N/m springs and euler over 0.1 s never ended;
    now its reference meets its budget and the command ends with exit 1 and one line naming it."""
    code, out, err = run_cli(["run", "-q", "--set", "simulation.accuracy=1e-3", "--set", "springs[0].stiffness=1e10",
                              "--set", "springs[1].stiffness=1e10", "--set", "simulation.integrator='euler'",
                              "--set", "simulation.duration=0.1"], capsys)
    assert code == 1, err
    line = err.strip().splitlines()[-1]
    assert line.startswith("coopctrl: failed: simulation.accuracy: ") and "beyond its budget" in line
