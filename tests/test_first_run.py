"""The first run of a kind says what it compiles; the summary's wall time leaves the start-up out
(coopctrl.cli.first_run, coopctrl.loop.startup, the summary's ``startup_s``)."""

from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys
import time

from coopctrl import cli
from coopctrl.cli import first_run
from coopctrl.loop import kernel, startup
from coopctrl.loop.startup import KernelKind
from coopctrl.results import summary_table
from coopctrl.scenario import Scenario
from coopctrl.scenario.loader import load_scenario

from test_cli import REPO


class _Terminal(io.StringIO):
    """A stream that says it is a terminal (the ticker draws only there)."""

    def isatty(self) -> bool:
        return True


def test_a_cold_kind_is_announced_in_one_line_and_a_warm_one_not_at_all(tmp_path):
    scenes = [Scenario(), load_scenario(None, {"simulation.integrator": "euler"})]
    stream = io.StringIO()  # not a terminal: the line only, no ticker
    notice = first_run.announce(scenes, stream=stream, directory=tmp_path)
    assert notice is not None
    notice.close()
    lines = stream.getvalue().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith("coopctrl: compiling the planar closed-loop kernels (explicit integrators: euler, rk4)")
    assert f"for this machine: {first_run.about(first_run.estimate_s([KernelKind('planar', 'explicit')]))} once; " \
        f"later runs load them from {tmp_path}" in lines[0]
    (tmp_path / "loop_0").mkdir()
    (tmp_path / "loop_0" / "kernel.run_ticks-1.py311.nbi").write_bytes(b"")
    startup.record_warm(KernelKind("planar", "explicit"), tmp_path)
    quiet = io.StringIO()
    assert first_run.announce(scenes, stream=quiet, directory=tmp_path) is None
    assert quiet.getvalue() == ""
    # the implicit kind is still cold; a kind is warm already: the second figure
    implicit = load_scenario(None, {"simulation.integrator": "implicit_euler"})
    first_run.announce([*scenes, implicit], stream=quiet, directory=tmp_path).close()
    assert quiet.getvalue().splitlines() == [first_run.notice_line(
        {KernelKind("planar", "implicit"): {"implicit_euler"}}, tmp_path, [KernelKind("planar", "explicit")])]


def test_on_a_terminal_a_ticker_runs_until_the_start_up_ends_and_is_erased(tmp_path, monkeypatch):
    monkeypatch.setattr(first_run, "TICK_S", 0.01)
    terminal = _Terminal()
    notice = first_run.announce([Scenario()], stream=terminal, directory=tmp_path)
    deadline = time.monotonic() + 60.0  # the ticker draws within 0.01 s; a bound, not a measurement
    while "compiling: " not in terminal.getvalue() and time.monotonic() < deadline:
        time.sleep(0.01)
    startup.started(KernelKind("planar", "explicit"), 0.0, tmp_path)  # the run's kernels are ready
    drawn = terminal.getvalue()
    assert drawn.count("\n") == 1 and "\r  compiling: " in drawn
    assert drawn.endswith("\r"), "the ticker's line is erased"
    notice.close()  # idempotent; nothing more is drawn
    time.sleep(0.05)
    assert terminal.getvalue() == drawn


def test_the_json_summary_carries_the_start_up_and_the_wall_time_leaves_it_out(capsys, monkeypatch):
    """In-process and warm (the kernels are loaded, not compiled): a start-up made at least SLOW_S long
    (the stages are built SLOW_S later) is in ``startup_s`` and not in ``wall_time_s``."""
    SLOW_S = 0.5
    original = kernel.tick_stages

    def slow_stages(*args, **kwargs):
        time.sleep(SLOW_S)
        return original(*args, **kwargs)

    monkeypatch.setattr(kernel, "tick_stages", slow_stages)
    monkeypatch.setattr(startup, "is_cold", lambda kind, directory=None: False)  # warm: no notice
    began = time.perf_counter()
    assert cli.main(["run", "--json", "--no-preflight", "--set", "simulation.duration=0.05"]) == 0
    total = time.perf_counter() - began
    out = capsys.readouterr()
    assert out.err == ""
    summary = json.loads(out.out)
    # time.sleep sleeps at least SLOW_S: the start-up holds it, and the whole call bounds both figures
    assert summary["startup_s"] >= SLOW_S
    assert 0.0 < summary["wall_time_s"] <= total - SLOW_S
    assert summary["realtime_factor"] == summary["simulated_time_s"] / summary["wall_time_s"]
    row = [line for line in summary_table(summary).splitlines() if line.startswith("startup (compile or load)")]
    assert len(row) == 1 and row[0].endswith(" s"), row


def test_a_first_run_says_what_it_compiles_and_a_second_run_says_nothing(tmp_path):
    """A run whose kind has no stamp announces it in one line on stderr; the same command again, on the
    cache that run left, prints nothing there. The cache is a copy of the suite's own without its
    stamps (the notice reads the stamps alone, :func:`coopctrl.loop.startup.is_cold`): its compiled
    files are loaded, not compiled again (a truly empty cache costs a minute of compiling, which
    ``benchmarks/bench_startup.py`` measures and the README's first command shows); run alone, with
    the suite's cache still empty, this test compiles them."""
    source = startup.cache_directory()
    target = tmp_path / source.name
    if source.is_dir():
        shutil.copytree(source, target, ignore=shutil.ignore_patterns(startup.STAMP_FOLDER))
    assert not (target / startup.STAMP_FOLDER).exists()
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path),
           "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    command = [sys.executable, "-m", "coopctrl", "run", "--set", "simulation.duration=0.05"]
    cold = subprocess.run(command, capture_output=True, text=True, env=env, cwd=REPO, timeout=900)
    assert cold.returncode == 0, cold.stderr
    lines = cold.stderr.splitlines()
    assert len(lines) == 1, cold.stderr
    assert lines[0].startswith("coopctrl: compiling the planar closed-loop kernels (explicit integrators: rk4) "
                               "for this machine: about ")
    assert f"later runs load them from {tmp_path}" in lines[0]
    assert "startup (compile or load)" in cold.stdout
    warm = subprocess.run(command, capture_output=True, text=True, env=env, cwd=REPO, timeout=900)
    assert warm.returncode == 0 and warm.stderr == "", warm.stderr


def test_the_machine_factor_is_the_median_of_the_first_runs_kept(tmp_path):
    times = tmp_path / first_run.TIMES_FILE
    assert first_run.machine_factor(times) == 1.0  # no file: the figures as they are
    times.write_text("planar-explicit 59.0 118.0\nspatial-explicit 88.0 198.0\nplanar-implicit 20.0 30.0\n"
                     "garbage\nplanar-explicit 0 5\nspatial-explicit 10 nan\nplanar-explicit -1 -9\n"
                     "planar-explicit 1e-320 1e300\n")
    assert first_run.machine_factor(times) == 2.0  # ratios 2, 2.25 and 1.5; the bad lines left out
    times.write_text("planar-explicit 1.0 100.0\n")
    assert first_run.machine_factor(times) == first_run.FACTOR_RANGE[1]
    times.write_bytes(b"\xff\xfe not text")
    assert first_run.machine_factor(times) == 1.0
    times.write_text("planar-explicit 59.0 177.0\n" + "x" * (2 * first_run.TIMES_READ_BYTES))  # read up to a bound
    assert first_run.machine_factor(times) == 3.0
    for i in range(first_run.TIMES_KEPT + 3):
        first_run.record_first_run(times, "planar-explicit", 59.0, float(i))
    lines = times.read_text().splitlines()
    assert lines == [f"planar-explicit 59.0 {i:.1f}" for i in range(3, first_run.TIMES_KEPT + 3)]


def test_a_notice_scales_its_estimate_by_the_machine_and_keeps_the_time_of_a_first_run(tmp_path, monkeypatch):
    """The estimate is the figures times this machine's factor; the time from the notice to the end of the
    kind's start-up is kept when numba compiled meanwhile (here a stated 0.2 s compile event, with the
    least kept compile lowered to 0.1 s), and not when it compiled nothing."""
    from numba.core import event

    planar = KernelKind("planar", "explicit")
    times, cache = tmp_path / "times.txt", tmp_path / "cache"
    times.write_text("planar-explicit 59.0 118.0\n")  # this machine took twice the figure
    stream = io.StringIO()
    notice = first_run.announce([Scenario()], stream=stream, directory=cache, times_file=times)
    assert f"for this machine: {first_run.about(2.0 * first_run.estimate_s([planar]))} once; " in stream.getvalue()
    assert "about 2 min" in stream.getvalue()  # 2 x 59 s
    monkeypatch.setattr(first_run, "LEAST_COMPILE_S", 0.1)
    event.start_event("numba:compile", data={"dispatcher": None, "args": None, "return_type": None})
    time.sleep(0.2)
    event.end_event("numba:compile", data={"dispatcher": None, "args": None, "return_type": None})
    startup.started(KernelKind("spatial", "explicit"), 0.0, cache)  # another kind: not this notice's
    assert times.read_text().splitlines() == ["planar-explicit 59.0 118.0"]
    startup.started(planar, 0.0, cache)
    notice.close()
    kept = times.read_text().splitlines()
    assert len(kept) == 2 and kept[1].startswith("planar-explicit 59.0 ")
    assert float(kept[1].split()[2]) >= 0.2  # the notice to the end of the start-up, the compile included
    # nothing compiled between the notice and the start-up's end: nothing kept
    monkeypatch.setattr(first_run, "LEAST_COMPILE_S", 5.0)
    notice = first_run.announce([Scenario()], stream=io.StringIO(), directory=cache, times_file=times)
    startup.started(planar, 0.0, cache)
    notice.close()
    assert times.read_text().splitlines() == kept


def test_a_sweeps_notice_is_scaled_by_the_kept_times(tmp_path):
    """A sweep's notice is scaled by this machine's kept times as a run's is, and only reads them (a fresh
    process on an empty cache folder, so its kind is cold; nothing runs)."""
    times = tmp_path / first_run.TIMES_FILE
    times.write_text("planar-explicit 59.0 118.0\n")  # twice the figure
    code = ("import sys; from coopctrl.cli import first_run; from coopctrl.sweep import SweepGrid; "
            "from coopctrl.sweep.worker import simulate_run; "
            "notice = first_run.announce_sweep(None, SweepGrid.parse(['simulation.seed=0,1']), [], simulate_run, "
            "ticker=False); notice.close()")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path),
           "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=REPO, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "coopctrl: compiling the planar closed-loop kernels (explicit integrators: rk4) for this machine: " \
        "about 2 min once" in done.stderr
    assert times.read_text() == "planar-explicit 59.0 118.0\n"
