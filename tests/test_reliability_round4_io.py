"""Reliability round 4 (issue 45), the command line's side: a sweep that survives a lost worker, every
echoed path and name escaped, the environment named as such, and ``check`` refusing what ``run`` refuses
before its first tick, with messages that name the field the user wrote. Each class has a seeded fuzz
test through the command line (``cli.main`` with its exit code, or a ``python -m coopctrl`` process).
"""

from __future__ import annotations

import json
import os
import random
import subprocess
import sys
from pathlib import Path

import pytest

import _lost_worker
from coopctrl import cli
from coopctrl.io.console import visible
from coopctrl.sweep import SweepGrid, run_sweep

REPO = Path(__file__).resolve().parent.parent
TESTS = Path(__file__).resolve().parent
LIFT = REPO / "scenarios" / "planar_two_arm_lift.toml"
SHORT = ["--set", "simulation.duration=0.05"]
ENV = {**os.environ, "PYTHONPATH": os.pathsep.join([str(REPO), str(TESTS), os.environ.get("PYTHONPATH", "")])}
#: Bound on one command [s]: a hang is what it catches, not slowness (a busy machine).
BOUND_S = 300


def run_cli(args, capsys):
    """``coopctrl ARGS`` in this process: (exit code, stdout, stderr)."""
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def one_clean_line(err: str) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err and "internal error" not in err, err
    assert len(lines) == 1, err
    return lines[0]


# ---------------------------------------------------------------------- 4. a sweep survives a lost worker
def _kill_env(monkeypatch, tmp_path, runs, simulate: bool = False) -> None:
    """Tell the workers (through their inherited environment) which runs kill their worker."""
    monkeypatch.setenv("COOPCTRL_TEST_KILL_RUNS", ",".join(map(str, runs)))
    monkeypatch.setenv("COOPCTRL_TEST_KILL_ONCE_DIR", str(tmp_path))
    monkeypatch.setenv("COOPCTRL_TEST_KILL_SIMULATE", "1" if simulate else "0")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_fuzz_a_worker_killed_once_is_retried_and_no_row_is_lost(seed, tmp_path, monkeypatch, capsys):
    """A seeded grid of 4 to 7 runs on 2 workers; one seeded run SIGKILLs its worker the first time it
    executes. Every row is the run's own (its figure identifies it), the victim was retried, exit 0."""
    rng = random.Random(seed)
    runs = rng.randint(4, 7)
    victim = rng.randrange(runs)
    _kill_env(monkeypatch, tmp_path, [victim])
    monkeypatch.setattr(cli.sweep, "worker_function", lambda: _lost_worker.kill_once)
    grid = "simulation.seed=" + ",".join(str(rng.randrange(10**6)) for _ in range(runs))
    code, out, err = run_cli(["sweep", LIFT, "--grid", grid, "--jobs", "2", "--json"], capsys)
    assert code == 0, err
    document = json.loads(out)
    rows = document["rows"]
    assert [r["run"] for r in rows] == list(range(runs)) and document["complete"] is True
    assert [r["status"] for r in rows] == ["ok"] * runs
    assert [r["object_position_error_rms_m"] for r in rows] == [k * 1e-3 for k in range(runs)]
    assert (tmp_path / f"killed-{victim}").is_file()  # it did kill its worker once
    retried = {entry["run"]: entry["cause"] for entry in document["retried"]}
    assert victim in retried and retried[victim] == "was killed by signal 9 (SIGKILL)"
    assert len(retried) <= 2  # the victim and at most the run in flight on the other worker
    assert err.splitlines()[-1].startswith("coopctrl: retried in a fresh worker after a worker process died: ")
    assert "BrokenProcessPool" not in out + err


@pytest.mark.parametrize("seed", [3, 4])
def test_fuzz_a_run_that_always_kills_its_worker_fails_alone(seed, tmp_path, monkeypatch, capsys):
    """A run that kills its worker every time: retried once, alone, then an ``error`` row naming both
    deaths; every other run keeps its result; the sweep exits 1 (a run failed for a reason of its own)."""
    rng = random.Random(seed)
    runs = rng.randint(4, 6)
    victim = rng.randrange(runs)
    _kill_env(monkeypatch, tmp_path, [victim])
    monkeypatch.setattr(cli.sweep, "worker_function", lambda: _lost_worker.kill_always)
    code, out, err = run_cli(["sweep", LIFT, "--grid", "simulation.seed=" + ",".join(map(str, range(runs))),
                              "--jobs", "2", "--json"], capsys)
    assert code == 1, err
    rows = json.loads(out)["rows"]
    assert [r["status"] for r in rows] == ["error" if k == victim else "ok" for k in range(runs)]
    reason = rows[victim]["reason"]
    # each death named by its signal, or, where the system had not yet let the exit code be read, as a death
    assert reason.startswith("the run's worker process died twice")
    assert 1 <= reason.count("signal 9 (SIGKILL)") + reason.count("a worker of its pool died") <= 2
    assert "signal 9 (SIGKILL)" in reason
    assert [r["object_position_error_rms_m"] for r in rows if r["run"] != victim] == \
        [k * 1e-3 for k in range(runs) if k != victim]
    assert err.splitlines()[-1] == f"coopctrl: 1 of {runs} runs failed (see their status and reason)"


def test_killed_worker_in_a_real_sweep_process(tmp_path):
    """``coopctrl sweep --jobs 2`` in its own process, simulating for real: run 1's worker SIGKILLs itself
    once. The rows (figures and all) equal those of the same sweep run serially, run 1 was retried, and
    sweep.json in --out holds the same rows; exit 0."""
    env = {**ENV, "COOPCTRL_TEST_KILL_RUNS": "1", "COOPCTRL_TEST_KILL_ONCE_DIR": str(tmp_path),
           "COOPCTRL_TEST_KILL_SIMULATE": "1"}
    program = ("import sys, _lost_worker, coopctrl.cli.sweep as s; s.worker_function = lambda: _lost_worker.kill_once; "
               "from coopctrl.cli import console_main; sys.argv[0] = 'coopctrl'; console_main()")
    grid = "simulation.seed=0,1,2,3"
    out = tmp_path / "sweep"
    proc = subprocess.run([sys.executable, "-c", program, "sweep", str(LIFT), "--grid", grid, *SHORT, "--jobs", "2",
                           "--json", "--out", str(out)], capture_output=True, text=True, env=env, timeout=BOUND_S)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "killed-1").is_file()
    document = json.loads(proc.stdout)
    assert 1 in [entry["run"] for entry in document["retried"]]
    serial = run_sweep(LIFT, SweepGrid.parse([grid]), sets={"simulation.duration": "0.05"}, jobs=1)
    timing = ("realtime_factor", "wall_time_s")
    assert [{k: v for k, v in r.items() if k not in timing} for r in document["rows"]] == serial.reproducible_rows()
    assert json.loads((out / "sweep.json").read_text())["rows"] == document["rows"]
    assert "retried in a fresh worker" in proc.stderr and "Traceback" not in proc.stderr


# ---------------------------------------------------------------------- 5. every printed path and name escaped
#: Pieces of hostile names: terminal escape sequences, bells, line breaks, C1 controls, bidirectional
#: overrides and isolates, invisible marks, and ordinary text (ASCII and not).
HOSTILE = ["\x1b[31m", "\x1b]0;title\x07", "\x07", "\r", "\x9b2J", "\u202e", "\u2066", "\u2069", "\u200f", "\u061c",
           "\x7f", "\t", "abc", "r\u00e9sultat", "run 1", "-"]


def hostile_name(rng: random.Random) -> str:
    name = "".join(rng.choice(HOSTILE) for _ in range(rng.randint(2, 5)))
    return "x" + name.replace("/", "_") + rng.choice(HOSTILE[:11])  # at least one hostile character


def assert_all_visible(text: str) -> None:
    """Nothing in ``text`` that a terminal would act on or hide: every character printable, line ends apart."""
    for line in text.split("\n"):
        bad = [c for c in line if not c.isprintable()]
        assert not bad, f"raw {[hex(ord(c)) for c in bad]} in {line!r}"


def test_visible_escapes_every_acting_character():
    assert visible("a\x1b[31mb\u202ec\x07\n\udcff") == "a\\x1b[31mb\\u202ec\\x07\\n\\udcff"
    assert visible("r\u00e9sultat / run 1") == "r\u00e9sultat / run 1"  # printable text is unchanged


@pytest.mark.parametrize("seed", range(4))
def test_fuzz_sweep_out_and_scene_file_names_are_escaped(seed, tmp_path, monkeypatch, capsys):
    """A sweep's --out with a hostile seeded name ("rows written to ..."), a hostile scene file for `list`
    and a hostile --dir that does not exist (the error line): all echoed visibly."""
    rng = random.Random(seed)
    out = tmp_path / hostile_name(rng)
    monkeypatch.setattr(cli.sweep, "worker_function", lambda: _lost_worker.fake_summary)
    code, stdout, err = run_cli(["sweep", LIFT, "--grid", "simulation.seed=0,1", "--jobs", "1", "--out", out], capsys)
    assert code == 0, err
    assert_all_visible(stdout + err)
    assert f"rows written to {visible(out / 'sweep.csv')}" in stdout and (out / "sweep.csv").is_file()
    scenes = tmp_path / "scenes"
    scenes.mkdir()
    name = hostile_name(rng)
    (scenes / f"{name}.toml").write_text(LIFT.read_text())
    code, stdout, err = run_cli(["list", "--dir", scenes], capsys)
    assert code == 0, err
    assert_all_visible(stdout + err)
    assert stdout.startswith(visible(name))
    code, stdout, err = run_cli(["list", "--dir", tmp_path / hostile_name(rng)], capsys)
    assert code == 2 and stdout == ""
    assert_all_visible(err)


@pytest.mark.parametrize("seed", [0])
def test_fuzz_run_out_and_scene_name_are_escaped(seed, tmp_path, capsys):
    """`run --out` ("outputs written to ...") and `check` of a scene whose name holds a bidirectional
    override (a scene may hold any printable text in its name: U+202E is not a control character)."""
    rng = random.Random(seed)
    out = tmp_path / hostile_name(rng)
    code, stdout, err = run_cli(["run", LIFT, *SHORT, "--out", out], capsys)
    assert code == 0, err
    assert_all_visible(stdout + err)
    assert f"outputs written to {visible(out)}" in stdout and (out / "result.npz").is_file()
    code, stdout, err = run_cli(["check", LIFT, "--set", 'name="lift\u202egnp.exe"'], capsys)
    assert code == 0, err
    assert_all_visible(stdout + err)
    assert stdout.startswith("ok: lift\\u202egnp.exe (")


# ---------------------------------------------------------------------- 6. the environment named as such
def _process(args, stdout, **kw):
    return subprocess.run([sys.executable, "-m", "coopctrl", *map(str, args)], stdout=stdout, stderr=subprocess.PIPE,
                          text=True, env=ENV, timeout=BOUND_S, **kw)


SINKS = {
    "full": ("no space left on device writing standard output", None),
    "closed": ("bad file descriptor writing standard output (it is closed)", None),
    "pipe": ("broken pipe writing standard output (the program reading it stopped, e.g. `head`)", None),
}
COMMANDS = [["list"], ["show", "planar_two_arm_lift"], ["check", "planar_two_arm_lift"],
            ["sweep", "planar_two_arm_lift", "--grid", "simulation.seed=0", "--jobs", "1", *SHORT]]
#: Commands whose whole output is argparse's (its help).
ARGPARSE_COMMANDS = [["--help"], ["run", "--help"]]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/dev/full")
@pytest.mark.parametrize("seed", range(4))
def test_fuzz_a_refused_standard_output_is_one_line_exit_1(seed):
    """A seeded command with its standard output on /dev/full, closed, or a pipe whose reader is gone:
    exit 1 and one line naming standard output and the cause (never "internal error")."""
    rng = random.Random(seed)
    command = rng.choice(COMMANDS)
    sink = rng.choice(sorted(SINKS))
    if sink == "full":
        with open("/dev/full", "w") as full:
            proc = _process(command, full)
    elif sink == "closed":
        proc = subprocess.run(["sh", "-c", 'exec "$0" "$@" >&-', sys.executable, "-m", "coopctrl", *command],
                              stderr=subprocess.PIPE, text=True, env=ENV, timeout=BOUND_S)
    else:
        read, write = os.pipe()
        os.close(read)  # the reader is gone before the first write: EPIPE, deterministically
        try:
            proc = _process(command, write)
        finally:
            os.close(write)
    assert proc.returncode == 1, (command, sink, proc.stderr)
    assert one_clean_line(proc.stderr).startswith("coopctrl: failed: " + SINKS[sink][0]), (command, sink)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/dev/full")
@pytest.mark.parametrize("command", ARGPARSE_COMMANDS, ids=" ".join)
@pytest.mark.parametrize("sink", sorted(SINKS))
def test_help_on_a_refused_standard_output_exits_1(command, sink):
    """``--help`` is written by argparse, whose own writer drops a refused write: on
    /dev/full, a closed standard output or a pipe whose reader is gone it exits 1 with the one line too (with
    ``PYTHONUNBUFFERED=1`` the write itself fails, before any flush)."""
    env = {**ENV, "PYTHONUNBUFFERED": "1"}
    if sink == "full":
        with open("/dev/full", "w") as full:
            proc = subprocess.run([sys.executable, "-m", "coopctrl", *command], stdout=full, stderr=subprocess.PIPE,
                                  text=True, env=env, timeout=BOUND_S)
    elif sink == "closed":
        proc = subprocess.run(["sh", "-c", 'exec "$0" "$@" >&-', sys.executable, "-m", "coopctrl", *command],
                              stderr=subprocess.PIPE, text=True, env=env, timeout=BOUND_S)
    else:
        read, write = os.pipe()
        os.close(read)
        try:
            proc = subprocess.run([sys.executable, "-m", "coopctrl", *command], stdout=write,
                                  stderr=subprocess.PIPE, text=True, env=env, timeout=BOUND_S)
        finally:
            os.close(write)
    assert proc.returncode == 1, (command, sink, proc.stderr)
    assert one_clean_line(proc.stderr).startswith("coopctrl: failed: " + SINKS[sink][0]), (command, sink)


@pytest.mark.parametrize("seed", range(2))
def test_fuzz_a_full_disk_under_a_sweep_is_one_line_exit_1(seed, tmp_path, monkeypatch, capsys):
    """The disk fills while the sweep saves its rows (ENOSPC from the system at a seeded save): exit 1,
    one line naming the file and the cause, the rows finished so far on stdout."""
    import errno

    from coopctrl.sweep import results

    rng = random.Random(seed)
    fail_at = rng.randint(1, 3)
    saves = []
    real_fsync = os.fsync

    def fsync(fd):
        saves.append(fd)
        if len(saves) >= fail_at:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        return real_fsync(fd)

    monkeypatch.setattr(results.os, "fsync", fsync)
    monkeypatch.setattr(cli.sweep, "worker_function", lambda: _lost_worker.fake_summary)
    out = tmp_path / "rows"
    code, stdout, err = run_cli(["sweep", LIFT, "--grid", "simulation.seed=0,1,2,3", "--jobs", "1", "--out", out], capsys)
    assert code == 1
    line = one_clean_line(err)
    assert line.startswith(f"coopctrl: failed: no space left on device writing {out / 'sweep.csv'}"), line
    assert "the sweep stopped after" in line and stdout.startswith("run  simulation.seed")
    assert not [p for p in tmp_path.iterdir() if p.name != "rows"]  # no temporary folder left beside it


def test_an_os_error_is_the_environment_not_a_bug(tmp_path, monkeypatch, capsys):
    """Any OSError that reaches the command line (here: a read-only file system met while `list` reads a
    scene) is one line naming the path, escaped, and the cause; exit 1."""
    import errno

    from coopctrl.scenario import scene_file

    def refuse(path):
        raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(tmp_path / "r\x1bo"))

    monkeypatch.setattr(scene_file, "scene_description", refuse)
    code, _, err = run_cli(["list"], capsys)
    assert code == 1
    assert one_clean_line(err) == f"coopctrl: failed: read-only file system: {tmp_path}/r\\x1bo"


def test_an_unwritable_result_folder_is_one_line_exit_1(tmp_path, monkeypatch, capsys):
    """`view` on a result folder the system will not let it write (EACCES while writing replay.html): exit 1,
    one line naming the file and the cause; the folder is as it was."""
    import errno

    from coopctrl.io.console import OutputWriteError
    from coopctrl.results import folder

    out = tmp_path / "result"
    code, _, err = run_cli(["run", LIFT, *SHORT, "-q", "--out", out], capsys)
    assert code == 0, err
    before = sorted(p.name for p in out.iterdir())

    def refuse(result, scenario, directory):
        raise OutputWriteError(str(directory / "replay.html"), PermissionError(errno.EACCES, os.strerror(errno.EACCES)))

    monkeypatch.setattr(folder, "rewrite_replay", refuse)
    code, stdout, err = run_cli(["view", out], capsys)
    assert code == 1 and stdout == ""
    assert one_clean_line(err) == f"coopctrl: failed: permission denied writing {out / 'replay.html'}; {out} was left as it was"
    assert sorted(p.name for p in out.iterdir()) == before


# ---------------------------------------------------------------------- 7. check is run without the run
class _FirstTick(Exception):
    """Raised where `run` would start simulating: everything before was pre-run checking."""


#: Overrides that `run` refuses before its first tick (bad input, a record too large, pre-flight) and some
#: that it accepts; each case is a seeded pick of one of them with a seeded harmless change beside it.
CASES = [
    {"simulation.duration": "1e4", "simulation.control_period": "1e-6"},  # a record of 1e10 samples
    {"simulation.duration": "9000", "simulation.control_period": "1e-5"},
    {"simulation.accuracy": "1e-300"},
    {"simulation.accuracy": "1e-13"},
    {"arms[1].grasp_error": "[3.0, 0.0, 0.0]"},
    {"arms[1].grasp_error": "[0.0, -2.5, 0.0]"},
    {"arms[0].grasp": "[-4.0, 0.0, 0.0]"},
    {"object.mass": "400"},  # pre-flight: the torques
    {"trajectory.via": "[{time=0.0,pose=[0,0.35,0]},{time=0.008,pose=[0,0.35,0]},{time=0.009,pose=[0,0.35,0]}]",
     "simulation.duration": "0.05"},  # segments of exactly one period: accepted
    {"simulation.duration": "0.05"},  # accepted
]


@pytest.mark.parametrize("seed", range(6))
def test_fuzz_check_refuses_what_run_refuses_before_the_first_tick(seed, monkeypatch, capsys):
    rng = random.Random(seed)
    case = dict(rng.choice(CASES))
    case.setdefault("simulation.seed", str(rng.randrange(1000)))
    sets = [a for path, value in case.items() for a in ("--set", f"{path}={value}")]

    def first_tick(*args, **kwargs):
        raise _FirstTick

    monkeypatch.setattr(cli.run, "simulate_function", lambda: first_tick)
    run_code, _, run_err = run_cli(["run", LIFT, "-q", *sets], capsys)
    check_code, check_out, check_err = run_cli(["check", LIFT, *sets], capsys)
    if "_FirstTick" in run_err:  # run reached its first tick: check passes
        assert check_code == 0 and check_out.startswith("ok: "), (case, check_err)
        return
    assert run_code in (1, 2) and check_code == run_code, (case, run_err, check_err)
    run_line, check_line = one_clean_line(run_err), one_clean_line(check_err)
    assert run_line.startswith(check_line), (case, run_line, check_line)  # run adds "(--no-preflight ...)"
    assert "time >=" not in check_line and " target " not in check_line


def test_messages_name_the_field_the_user_wrote(capsys):
    code, _, err = run_cli(["check", LIFT, "--set", "arms[1].grasp_error=[3.0, 0.0, 0.0]"], capsys)
    line = one_clean_line(err)
    assert code == 2 and "arms[1].grasp_error = [3.0, 0.0, 0.0] is invalid" in line and "arms[1].grasp =" not in line
    code, _, err = run_cli(["check", LIFT, "--set", "simulation.accuracy=1e-300"], capsys)
    line = one_clean_line(err)
    assert code == 2 and "simulation.accuracy = 1e-300 is invalid: expected a finite number >= 1e-12 and <= 1" in line
    doc = (REPO / "docs" / "scenario.md").read_text()
    assert "| `simulation.accuracy` | float, optional | m | absent | >= 1e-12 and <= 1 |" in doc  # the same range


@pytest.mark.parametrize("seed", range(3))
def test_fuzz_via_points_at_whole_periods_are_not_refused(seed, capsys):
    """Via times at k x 1 ms (decimal, not binary multiples of the period): a segment of one period is
    accepted; one of half a period is refused naming the time."""
    from coopctrl.scenario import load_scenario

    rng = random.Random(seed)
    ticks = sorted(rng.sample(range(1, 60), 3))
    via = "[{time=0.0,pose=[0,0.35,0]}," + ",".join(
        f"{{time={k / 1000},pose=[0,0.35,0]}}" for k in ticks) + f",{{time={(ticks[-1] + 1) / 1000},pose=[0,0.35,0]}}]"
    load_scenario(LIFT, {"trajectory.via": via, "simulation.duration": "0.07"})  # accepted
    half = via[:-1] + f",{{time={(ticks[-1] + 1.5) / 1000},pose=[0,0.35,0]}}]"
    code, _, err = run_cli(["check", LIFT, "--set", f"trajectory.via={half}", "--set", "simulation.duration=0.07"], capsys)
    assert code == 2 and f"trajectory.via[{len(ticks) + 2}].time" in one_clean_line(err)
