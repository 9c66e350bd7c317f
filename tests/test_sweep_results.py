"""``SweepResult.save`` (coopctrl/sweep/results.py): ``sweep.csv`` and ``sweep.json`` are written as one
unit, so they always hold the same rows, and an interruption leaves no temporary file or folder
(issue 22, torn or mixed output)."""

from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from coopctrl import cli
from coopctrl.cli import Terminated

from test_cli import REPO
from test_sweep import LIFT, fake_summary

ENV_PATH = str(REPO)


def _rows(directory):
    with open(directory / "sweep.csv", newline="") as handle:
        csv_runs = [int(row["run"]) for row in csv.DictReader(handle)]
    document = json.loads((directory / "sweep.json").read_text())
    return csv_runs, [row["run"] for row in document["rows"]], document


def _debris(*directories):
    return [p.name for d in directories if d.exists() for p in d.iterdir()
            if p.name.startswith(".") or p.name.endswith(".tmp")]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/fd")
def test_a_signal_inside_a_save_keeps_both_files_of_the_last_whole_save(tmp_path, capsys, monkeypatch):
    """SIGTERM lands while the second save writes sweep.json (its csv already written): the folder keeps
    the first save's two files, and no temporary file or folder is left."""
    import coopctrl.sweep.results as results

    out = tmp_path / "sweep"
    saves = []
    real_fsync = results.os.fsync

    def fsync(fd):
        if os.readlink(f"/proc/self/fd/{fd}").endswith("sweep.json"):
            saves.append(fd)
        if len(saves) == 2:  # sweep.json of the second save, its sweep.csv already written
            current = _rows(out)
            assert current[0] == current[1]  # what a reader sees at this moment: one save, whole
            raise Terminated(signal.SIGTERM)
        return real_fsync(fd)

    monkeypatch.setattr(results.os, "fsync", fsync)
    monkeypatch.setattr(cli.sweep, "worker_function", lambda: fake_summary)
    code = cli.main(["sweep", str(LIFT), "--grid", "simulation.seed=0,1,2,3,4,5", "--jobs", "1", "-q", "--out", str(out)])
    capsys.readouterr()
    assert code in (130, 143)
    csv_runs, json_runs, document = _rows(out)
    assert csv_runs == json_runs and document["finished"] == len(json_runs) >= 1
    assert _debris(out, tmp_path) == []


def test_save_replaces_an_earlier_sweep_and_refuses_other_files(tmp_path):
    from coopctrl.sweep import SweepGrid, run_sweep

    out = tmp_path / "sweep"
    run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1,2"]), jobs=1, run_function=fake_summary, out=out)
    run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1"]), jobs=1, run_function=fake_summary, out=out)
    csv_runs, json_runs, _ = _rows(out)
    assert csv_runs == json_runs == [0, 1]
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="notes.txt"):
        run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0"]), jobs=1, run_function=fake_summary, out=out)
    assert (out / "notes.txt").read_text() == "mine"


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals as on Linux")
def test_sigterm_during_a_sweep_leaves_no_temporary_file(tmp_path):
    """A real SIGTERM once the first rows are saved: exit 143, the two files agree, nothing else left."""
    out = tmp_path / "sweep"
    env = {**os.environ, "PYTHONPATH": ENV_PATH + os.pathsep + os.environ.get("PYTHONPATH", "")}
    command = [sys.executable, "-m", "coopctrl", "sweep", str(LIFT), "--grid", "simulation.seed=0,1,2,3,4,5,6,7,8,9",
               "--set", "simulation.duration=0.2", "--jobs", "1", "-q", "--out", str(out)]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        deadline = time.monotonic() + 300
        while not (out / "sweep.json").exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.02)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=300)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode in (0, 143), err  # 0: it finished before the signal (a very fast machine)
    assert "Traceback" not in err
    csv_runs, json_runs, _ = _rows(out)
    assert csv_runs == json_runs
    assert _debris(out, tmp_path) == []
