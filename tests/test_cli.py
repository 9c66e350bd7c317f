"""Tests of the coopctrl command line: subprocesses for user errors, in-process with a fake simulator."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from coopctrl import cli
from coopctrl.io import dumps_toml
from coopctrl.scenario import Scenario

REPO = Path(__file__).resolve().parent.parent


def coopctrl(*args, cwd=None):
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    return subprocess.run([sys.executable, "-m", "coopctrl", *map(str, args)], capture_output=True, text=True, env=env, cwd=cwd or REPO, timeout=600)


def assert_user_error(proc, *needles):
    assert proc.returncode == 2, proc
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith("coopctrl: error: ")
    for needle in needles:
        assert needle in lines[0], lines[0]
    assert proc.stdout == ""


@pytest.fixture
def scene(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(dumps_toml(Scenario().to_dict()))
    return path


def bad_scene(tmp_path, mutate):
    data = Scenario().to_dict()
    mutate(data)
    path = tmp_path / "bad.toml"
    path.write_text(dumps_toml(data))
    return path


# ---------------------------------------------------------------------- help
@pytest.mark.parametrize("args", [["--help"], ["run", "--help"], ["list", "--help"], ["check", "--help"]])
def test_help_exits_zero(args):
    proc = coopctrl(*args)
    assert proc.returncode == 0 and "usage: coopctrl" in proc.stdout


def test_every_registered_subcommand_has_help(capsys):
    assert cli.main(["no-such-command"]) == 2  # the usage error lists every registered subcommand
    listed = re.search(r"\(choose from (.*)\)", capsys.readouterr().err)
    assert listed, "the usage error of an unknown subcommand lists the choices"
    names = [name.strip(" '\"") for name in listed.group(1).split(",")]
    assert {"run", "list", "check", "sweep"} <= set(names)
    for name in names:
        assert cli.main([name, "--help"]) == 0



@pytest.mark.parametrize("argv", [
    ["run"], ["run", "planar_two_arm_lift", "-q", "--set", "simulation.duration=1", "--json"],
    ["check", "spatial_two_puma_carry"], ["list"], ["show", "planar_two_arm_lift"],
    ["sweep", "planar_two_arm_lift", "--grid", "simulation.seed=0,1", "--jobs", "2"],
    ["stability", "planar_two_arm_lift"], ["tradeoff"], ["fidelity", "planar_two_arm_lift"],
    ["view", "planar_two_arm_lift"],
])
def test_a_command_lines_parser_is_its_subcommands_alone(argv):
    """A command line builds its own subcommand's parser only (``build_parser(NAME)``: the other subcommands'
    options cost milliseconds to build); it parses the line as the whole parser does."""
    alone, whole = cli.build_parser(argv[0]), cli.build_parser()
    assert vars(alone.parse_args(argv)) == vars(whole.parse_args(argv))
    other = next(name for name in cli.SUBCOMMANDS if name != argv[0])
    with pytest.raises(cli.UsageError, match="invalid choice"):
        alone.parse_args([other])
    listing = whole.format_help()
    assert all(re.search(rf"^    {name}\b", listing, re.M) for name in cli.SUBCOMMANDS)  # the whole parser has them all

# ---------------------------------------------------------------------- check
def test_check_valid_file(scene):
    proc = coopctrl("check", scene)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("ok: default (planar, 2 arms, state size 18")


def test_check_with_override(scene):
    proc = coopctrl("check", scene, "--set", "simulation.integrator=euler", "--set", "springs[0].stiffness=1e6")
    assert proc.returncode == 0, proc.stderr


@pytest.mark.parametrize(
    "mutate, field",
    [
        (lambda d: d["arms"][1].update(grasp=[0.1, 0.0]), "arms[1].grasp"),
        (lambda d: d["springs"][0].update(stiffness=-1.0), "springs[0].stiffness"),
        (lambda d: d["simulation"].update(substeps=0), "simulation.substeps"),
        (lambda d: d["simulation"].update(bogus=1), "simulation.bogus"),
        (lambda d: d["arms"][1].update(role="leader"), "arms[1].role"),
        (lambda d: d["object"].update(mass=float("nan")), "object.mass"),
    ],
)
def test_check_bad_field(tmp_path, mutate, field):
    assert_user_error(coopctrl("check", bad_scene(tmp_path, mutate)), field)


def test_check_missing_file(tmp_path):
    assert_user_error(coopctrl("check", tmp_path / "nope.toml"), "nope.toml", "not found")


def test_check_toml_syntax_error(tmp_path):
    path = tmp_path / "broken.toml"
    path.write_text("[simulation\nduration = 1\n")
    assert_user_error(coopctrl("check", path), "broken.toml", "line 1")


@pytest.mark.parametrize(
    "setting, field",
    [
        ("simulation.integrator=rk89", "simulation.integrator"),  # rk45 is a scheme since the error-controlled ones
        ("springs[0].stiffness=abc", "springs[0].stiffness"),
        ("simulation.nope=1", "simulation.nope"),
        ("springs[9].stiffness=1", "springs[9].stiffness"),
        ("simulation.integrator", "--set"),
    ],
)
def test_bad_set(scene, setting, field):
    assert_user_error(coopctrl("check", scene, "--set", setting), field)


@pytest.mark.parametrize("args", [[], ["frobnicate"], ["check", "--bogus"], ["run", "--bogus"]])
def test_usage_errors_are_one_line(args):
    assert_user_error(coopctrl(*args))


def test_run_bad_input_exits_2_before_simulating(tmp_path):
    path = bad_scene(tmp_path, lambda d: d["simulation"].update(substeps=0))
    assert_user_error(coopctrl("run", path, "--json"), "simulation.substeps")
    assert_user_error(coopctrl("run", "--set", "simulation.integrator=leapfrog"), "simulation.integrator")


# ---------------------------------------------------------------------- list
def test_list_directory(tmp_path):
    (tmp_path / "b_scene.toml").write_text('description = "The second one."\n')
    (tmp_path / "a_scene.toml").write_text('name = "a"\ndescription = "The first one."\n')
    (tmp_path / "broken.toml").write_text("[[[")
    proc = coopctrl("list", "--dir", tmp_path)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].split() == ["a_scene", "The", "first", "one."]
    assert lines[1].startswith("b_scene ") and lines[2].startswith("broken ")
    assert "Traceback" not in proc.stderr


def test_list_builtin():
    proc = coopctrl("list")
    assert proc.returncode == 0 and "Traceback" not in proc.stderr


def test_builtin_scenarios_are_valid():
    """Every shipped scenario is valid input; its task passes pre-flight, except the buckling scene, which
    is meant to fail and is refused as impossible (exit 1, not 2)."""
    for path in sorted((REPO / "scenarios").glob("*.toml")):
        assert cli.main(["check", str(path)]) == (1 if path.stem == "central_spring_buckling" else 0), path


# ---------------------------------------------------------------------- run, with a fake simulator
@pytest.fixture
def fake_simulate(monkeypatch):
    from test_results import synthetic

    calls = []

    def install(status="ok", exc=None):
        def simulate(scenario, progress=False, loop=None, node_poses=True):  # the real simulate's signature
            calls.append((scenario, progress))
            if exc is not None:
                raise exc
            result = synthetic(status=status)
            result.scenario = scenario.name
            return result

        monkeypatch.setattr(cli.run, "simulate_function", lambda: simulate)
        return calls

    return install


def test_run_prints_table(fake_simulate, capsys):
    calls = fake_simulate()
    assert cli.main(["run", "--set", "simulation.integrator=euler"]) == 0
    out = capsys.readouterr()
    assert "status" in out.out and "ok" in out.out and out.err == ""
    scenario, progress = calls[0]
    assert scenario.simulation.integrator == "euler" and progress is False  # stderr is not a terminal


def test_run_json_only_json_on_stdout(fake_simulate, capsys, tmp_path):
    fake_simulate()
    assert cli.main(["run", "--json", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr()
    summary = json.loads(out.out)
    assert summary["status"] == "ok" and summary["scenario"] == "default"
    names = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert names == ["contact_forces.png", "joint_torques.png", "object_pose.png", "qp_solve_times.png",
                     "replay.html", "result.csv", "result.npz", "scenario.toml", "summary.json"]


def test_run_diverged_exits_1_with_one_line(fake_simulate, capsys):
    fake_simulate(status="diverged")
    assert cli.main(["run", "--quiet"]) == 1
    out = capsys.readouterr()
    assert out.out == ""
    assert out.err.splitlines() == ["coopctrl: diverged: deformation 0.06 m > 0.05 m at t = 0.19 s"]


def test_run_divergence_exception_exits_1(fake_simulate, capsys):
    from coopctrl.errors import DivergenceError

    fake_simulate(exc=DivergenceError(0.3, "max deformation", 0.07, 1e-4))
    assert cli.main(["run", "-q"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("coopctrl: diverged: diverged at t = 0.3 s")


def test_keyboard_interrupt_exits_130(fake_simulate, capsys):
    fake_simulate(exc=KeyboardInterrupt())
    assert cli.main(["run"]) == 130
    assert "Traceback" not in capsys.readouterr().err


def test_cli_import_is_light():
    code = (
        "import sys, coopctrl; before = set(sys.modules); import coopctrl.cli; "
        "new = set(sys.modules) - before; "
        "print(sorted(m for m in new if m.split('.')[0] in ('numpy', 'matplotlib', 'control', 'scipy', 'numba', 'tqdm')))"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, check=True)
    assert proc.stdout.strip() == "[]"


# ---------------------------------------------------------------------- run, with the real simulator
def test_run_default_scene_json(tmp_path):
    proc = coopctrl("run", "--json", "--out", tmp_path / "out", "--set", "simulation.duration=0.05")
    assert proc.returncode in (0, 1), proc.stderr
    assert "Traceback" not in proc.stderr
    summary = json.loads(proc.stdout)
    assert summary["status"] in ("ok", "diverged", "qp_failed")
    for name in ("result.npz", "result.csv", "summary.json", "object_pose.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    if proc.returncode == 1:
        assert len(proc.stderr.splitlines()) == 1


def test_run_default_scene_table():
    proc = coopctrl("run", "--set", "simulation.duration=0.05")
    assert proc.returncode in (0, 1), proc.stderr
    assert "status" in proc.stdout and "Traceback" not in proc.stderr


# ---------------------------------------------------------------------- bounds and fall-backs (issues 21, 22)
def _refused_in_process(capsys, args, *needles):
    assert cli.main([str(a) for a in args]) == 2, args
    out, err = capsys.readouterr()
    assert out == "" and len(err.splitlines()) == 1 and err.startswith("coopctrl: error: "), err
    for needle in needles:
        assert needle in err, err


@pytest.mark.parametrize("args, needles", [
    (["fidelity", "--calls", "1e12"], ["--calls", "'1e12' is invalid: expected an integer in 1..1000000"]),
    (["fidelity", "--calls", "1000001"], ["--calls", "1..1000000"]),
    (["fidelity", "--repeats", "101"], ["--repeats", "1..100"]),
    (["tradeoff", "--repeat", "0"], ["--repeat", "1..100"]),
    (["tradeoff", "--repeat", "1e9"], ["--repeat", "1..100"]),
    (["tradeoff", "--steps", ",".join(f"T/{n}" for n in range(1, 66))], ["--steps has 65 entries", "at most 64"]),
    (["tradeoff", "--steps", "T/4097"], ["--steps", "1..4096"]),
    (["sweep", "--jobs", "257", "--grid", "simulation.seed=0"], ["--jobs", "1..256"]),
    (["sweep", "--run-timeout", "1e9", "--grid", "simulation.seed=0"], ["--run-timeout", "<= 604800 s"]),
    (["sweep", "--run-timeout", "nan", "--grid", "simulation.seed=0"], ["--run-timeout"]),
    (["check", "--set", "simulation.substeps=1e9"], ["simulation.substeps"]),
])
def test_counts_and_sizes_of_options_have_ranges(capsys, args, needles):
    """Issue 22: `fidelity --calls 1e12` ran on without end; every count an option takes has a range."""
    _refused_in_process(capsys, args, *needles)


def test_every_command_falls_back_to_the_builtin_scene():
    """Issue 21 item 7: check, stability, tradeoff (and sweep) take no scenario as run and show do."""
    parser = cli.build_parser()
    for command in ("run", "show", "check", "stability", "tradeoff", "sweep"):
        assert parser.parse_args([command]).scenario is None, command


def test_check_without_a_scenario_checks_the_builtin_scene(capsys):
    assert cli.main(["check"]) == 0
    assert capsys.readouterr().out.startswith("ok: default (planar, 2 arms")


def test_list_refuses_a_missing_directory(tmp_path, capsys):
    _refused_in_process(capsys, ["list", "--dir", tmp_path / "missing"], "--dir", "an existing directory")
