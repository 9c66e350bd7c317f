"""Tests of parameter sweeps (coopctrl.sweep, ``coopctrl sweep``): grid parsing, the product, failed runs
as rows, independence from the number of jobs and from the executor (a local Dask cluster), and
interruption keeping the finished rows."""

from __future__ import annotations

import csv
import itertools
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from coopctrl import cli
from coopctrl.errors import ScenarioError
from coopctrl.sweep import (TIMING_COLUMNS, GridError, MissingExtra, SchedulerError, SerialExecutor, SweepGrid,
                            SweepInterrupted, make_executor, plan_sweep, run_sweep, split_values)
from test_cli import REPO, assert_user_error, coopctrl

LIFT = REPO / "scenarios" / "planar_two_arm_lift.toml"
HEAVY = REPO / "scenarios" / "heavy_payload_torque_limits.toml"

# A real sweep with one run of each kind: explicit Euler at a 5 ms period diverges at t = 0.24 s
# (deformation bound), a grasp 5 m away passes the field checks but not the inverse kinematics of
# the plant (a ScenarioError inside the worker: an ``error`` row), the rest is ok.
MIXED_GRID = ["simulation.control_period=0.001,0.005", "arms[1].grasp=[0.1,0,3.14],[5,0,3.14]"]
# The book's dampers leave a 217 rad/s mode of the lift at zeta 0.09, which explicit Euler at 5 ms cannot
# hold (the run at control_period 0.005 diverges); the frame-invariant default damps it (zeta 0.24).
MIXED_SETS = {"simulation.integrator": "euler", "simulation.duration": "0.3",
              "springs[0].damping_form": '"book"', "springs[1].damping_form": '"book"'}
MIXED_STATUSES = ["ok", "error", "diverged", "error"]


# ---------------------------------------------------------------------- grid
@pytest.mark.parametrize(
    "text, values",
    [
        ("rk4,euler", ("rk4", "euler")),
        (" 1e4 , 2e4 ", ("1e4", "2e4")),
        ("[0.1,0,3.14],[0.1,0,3.0]", ("[0.1,0,3.14]", "[0.1,0,3.0]")),
        ("[[1,2],[3]],[4]", ("[[1,2],[3]]", "[4]")),
        ("{a = 1, b = 2},{a = 3}", ("{a = 1, b = 2}", "{a = 3}")),
        ('"a,b",c', ('"a,b"', "c")),
        (r'"a\",b",c', (r'"a\",b"', "c")),
        ("'x,[y',z", ("'x,[y'", "z")),
        ("7", ("7",)),
    ],
)
def test_split_on_commas_at_depth_zero_outside_quotes(text, values):
    assert split_values(text) == values


def test_grid_values_are_toml_like_set():
    grid = SweepGrid.parse(["arms[1].grasp=[0.1,0,3.14],[0.1,0,3.0]", "simulation.integrator=rk4,euler",
                            "sensors.forces.noise_std=0,1e-2"])
    assert grid.to_dict() == {"arms[1].grasp": [[0.1, 0, 3.14], [0.1, 0, 3.0]], "simulation.integrator": ["rk4", "euler"],
                              "sensors.forces.noise_std": [0, 0.01]}


def test_product_count_and_order():
    grid = SweepGrid.parse(["a.x=1,2", "b.y=p,q,r", "c.z=[0,1]"])
    assert grid.paths == ("a.x", "b.y", "c.z") and len(grid) == 6
    expected = [dict(zip(grid.paths, combo)) for combo in itertools.product(["1", "2"], ["p", "q", "r"], ["[0,1]"])]
    assert list(grid.combinations()) == expected  # first axis slowest, last fastest
    assert len(SweepGrid()) == 1 and SweepGrid().combinations() == ({},)


def test_plan_applies_each_combination():
    grid = SweepGrid.parse(["simulation.integrator=rk4,euler", "springs[0].stiffness=1e4,3e4"])
    plan = plan_sweep(LIFT, grid, {"simulation.duration": "0.2"})
    assert plan.name == "planar_two_arm_lift" and [r.index for r in plan.runs] == [0, 1, 2, 3]
    got = [(s.simulation.integrator, s.springs[0].stiffness, s.simulation.duration) for s in (r.scenario() for r in plan.runs)]
    assert got == [("rk4", 1e4, 0.2), ("rk4", 3e4, 0.2), ("euler", 1e4, 0.2), ("euler", 3e4, 0.2)]
    assert plan.runs[3].columns == {"simulation.integrator": "euler", "springs[0].stiffness": 3e4}
    # a planned run carries the scenario its validation built, equal to the one built again from its data
    from dataclasses import replace

    assert all(r.checked is not None and replace(r, checked=None).scenario() == r.scenario() for r in plan.runs)


@pytest.mark.parametrize(
    "argument, needle",
    [
        ("simulation.duration", "PATH=V1,V2"),
        ("=1,2", "PATH=V1,V2"),
        ("simulation.duration=1,,2", "non-empty value"),
        ("simulation.duration=1,", "non-empty value"),
        ("arms[1].grasp=[0.1,0,3.14", "balanced brackets"),
        ("arms[1].grasp=0.1]", "balanced brackets"),
        ('name="a,b', "balanced quotes"),
        ("simulation..duration=1,2", "dotted PATH"),
        ("simulation.duration=0.1,0.1", "given twice"),
    ],
)
def test_bad_grid_is_one_line_naming_the_argument(argument, needle, capsys):
    assert cli.main(["sweep", str(LIFT), "--grid", argument]) == 2
    out = capsys.readouterr()
    lines = out.err.splitlines()
    assert len(lines) == 1 and out.out == "", out
    assert lines[0].startswith(f"coopctrl: error: --grid {argument!r} is invalid: expected ") and needle in lines[0]


def test_same_path_twice_is_an_error():
    with pytest.raises(GridError, match="already swept"):
        SweepGrid.parse(["simulation.duration=0.1,0.2", "simulation.duration =0.3"])
    with pytest.raises(GridError, match="not also fixed by --set"):
        plan_sweep(LIFT, SweepGrid.parse(["simulation.duration=0.1,0.2"]), {"simulation.duration": "0.3"})


def _recording(calls):
    def run_function(run):
        calls.append(run.index)
        return {"status": "ok", "reason": ""}

    return run_function


@pytest.mark.parametrize(
    "grid, needles",
    [
        # only run 1 is invalid (a period longer than the duration): nothing may run, not even run 0
        (["simulation.control_period=0.001,0.5"], ["run 1 (simulation.control_period=0.5)", "simulation.control_period = 0.5"]),
        (["simulation.nope=1,2"], ["simulation.nope", "known key"]),
        (["simulation.integrator=rk4,leapfrog"], ["simulation.integrator = 'leapfrog'"]),
    ],
)
def test_every_combination_is_validated_before_any_run(grid, needles, monkeypatch, capsys):
    calls = []
    monkeypatch.setattr(cli.sweep, "worker_function", lambda: _recording(calls))
    args = ["sweep", str(LIFT), "--set", "simulation.duration=0.3", "--jobs", "1"]
    assert cli.main(args + [a for g in grid for a in ("--grid", g)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and all(n in err[0] for n in needles), err
    assert calls == []


def test_jobs_and_scheduler_are_exclusive():
    assert_user_error(coopctrl("sweep", LIFT, "--grid", "simulation.duration=0.1", "--jobs", "0"), "--jobs", "integer in 1..256")
    both = coopctrl("sweep", LIFT, "--grid", "simulation.duration=0.1", "--jobs", "2", "--scheduler", "tcp://127.0.0.1:1")
    assert_user_error(both, "not allowed with argument")


# ---------------------------------------------------------------------- real runs
@pytest.fixture(scope="module")
def serial_mixed():
    """The mixed sweep in this process (jobs = 1)."""
    return run_sweep(LIFT, SweepGrid.parse(MIXED_GRID), sets=MIXED_SETS, jobs=1)


def test_failed_runs_are_rows_with_their_reason(serial_mixed):
    rows = serial_mixed.rows
    assert [r["run"] for r in rows] == [0, 1, 2, 3] and serial_mixed.complete
    assert [r["status"] for r in rows] == MIXED_STATUSES
    assert [r["simulation.control_period"] for r in rows] == [0.001, 0.001, 0.005, 0.005]
    assert [r["arms[1].grasp"] for r in rows] == [[0.1, 0, 3.14], [5, 0, 3.14]] * 2
    assert rows[2]["reason"].startswith("diverged at t = ") and "deformation" in rows[2]["reason"]
    assert rows[2]["simulated_time_s"] < 0.3  # stopped early; its figures up to then are kept
    for row in (rows[1], rows[3]):
        assert row["reason"].startswith("ScenarioError: ") and "arms[1].grasp" in row["reason"]
        assert row["object_position_error_rms_m"] is None and row["wall_time_s"] > 0
    assert rows[0]["reason"] == "" and rows[0]["simulated_time_s"] == pytest.approx(0.3)
    assert [r["run"] for r in serial_mixed.failed] == [1, 2, 3]


def test_ok_row_is_the_runs_own_summary(serial_mixed):
    """The ok row of the mixed sweep equals the summary of the same scenario simulated alone: the
    failed runs beside it changed nothing."""
    import coopctrl

    alone = coopctrl.simulate(coopctrl.load_scenario(LIFT, {**MIXED_SETS, "simulation.control_period": "0.001",
                                                            "arms[1].grasp": "[0.1,0,3.14]"})).summary()
    row = serial_mixed.rows[0]
    for key in ("object_position_error_rms_m", "object_position_error_max_m", "follower_force_error_rms_N",
                "internal_force_error_rms_N", "max_torque_ratio", "simulated_time_s"):
        assert row[key] == alone[key], key  # deterministic: same seed, same arithmetic, bit for bit


def test_jobs_1_and_2_give_identical_rows(serial_mixed, tmp_path):
    pooled = run_sweep(LIFT, SweepGrid.parse(MIXED_GRID), sets=MIXED_SETS, jobs=2, out=tmp_path)
    assert pooled.reproducible_rows() == serial_mixed.reproducible_rows()
    assert all(k not in row for row in pooled.reproducible_rows() for k in TIMING_COLUMNS)
    saved = json.loads((tmp_path / "sweep.json").read_text())
    assert saved["rows"] == [dict(r) for r in pooled.rows] and saved["complete"] is True


def test_same_rows_on_a_dask_cluster(serial_mixed, capsys):
    """A local Dask cluster on loopback: two worker processes, one thread each."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(host="127.0.0.1", n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        args = ["sweep", str(LIFT), "--json", "--scheduler", cluster.scheduler_address]
        args += [a for g in MIXED_GRID for a in ("--grid", g)] + [a for k, v in MIXED_SETS.items() for a in ("--set", f"{k}={v}")]
        code = cli.main(args)
    out = capsys.readouterr()
    assert code == 1, out.err  # runs failed: exit 1, their rows on stdout
    document = json.loads(out.out)
    rows = [{k: v for k, v in row.items() if k not in TIMING_COLUMNS} for row in document["rows"]]
    assert rows == serial_mixed.reproducible_rows()
    assert document["grid"] == {"simulation.control_period": [0.001, 0.005], "arms[1].grasp": [[0.1, 0, 3.14], [5, 0, 3.14]]}
    assert out.err.splitlines() == ["coopctrl: 3 of 4 runs failed (see their status and reason)"]


def test_unreachable_scheduler_names_the_address():
    pytest.importorskip("distributed")
    # port 9 (discard) on loopback: nothing listens there; 1 s is enough to be refused
    with pytest.raises(SchedulerError, match=r"--scheduler 'tcp://127\.0\.0\.1:9': cannot connect"):
        make_executor(scheduler="tcp://127.0.0.1:9", timeout_s=1.0)
    with pytest.raises(SchedulerError, match="missing port number"):
        make_executor(scheduler="no-port", timeout_s=1.0)


def test_missing_distributed_says_which_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(MissingExtra, match=r"pip install 'coopctrl\[distributed\]'"):
        make_executor(scheduler="tcp://127.0.0.1:8786")


def test_cli_end_to_end(tmp_path):
    """A subprocess with a pool of 2: a heavy payload of 60 kg has no feasible split within the
    torque limits (``qp_failed`` at t = 0), 8 kg is fine."""
    out = tmp_path / "sweep"
    proc = coopctrl("sweep", "heavy_payload_torque_limits", "--grid", "object.mass=8,60", "--set", "simulation.duration=0.1",
                    "--jobs", "2", "--out", out)
    assert proc.returncode == 1, proc.stderr  # a run failed (qp_failed): exit 1, the rows are whole
    assert proc.stderr.splitlines() == ["coopctrl: 1 of 2 runs failed (see their status and reason)"]
    lines = proc.stdout.splitlines()
    assert lines[0].split()[:3] == ["run", "object.mass", "status"]
    assert lines[1].split()[:3] == ["0", "8", "ok"] and lines[2].split()[:3] == ["1", "60", "qp_failed"]
    assert lines[3].startswith("run 1 qp_failed: at t = 0 s (loaded start): load distribution failed")
    with open(out / "sweep.csv", newline="") as handle:
        table = list(csv.DictReader(handle))
    assert [(r["run"], r["object.mass"], r["status"]) for r in table] == [("0", "8", "ok"), ("1", "60", "qp_failed")]
    assert table[1]["object_position_error_rms_m"] == ""  # None is an empty cell
    document = json.loads((out / "sweep.json").read_text())
    assert document["scenario"] == "heavy_payload_torque_limits" and document["set"] == {"simulation.duration": 0.1}
    assert document["rows"][1]["object_position_error_rms_m"] is None and document["failed"] == 1


# ---------------------------------------------------------------------- injected run functions
def fake_summary(run):
    """A run function that does not simulate: fast, and its figure identifies the run."""
    return {"status": "ok", "reason": "", "object_position_error_rms_m": run.index * 1e-3}


def raise_on_run_1(run):
    if run.index == 1:
        raise RuntimeError("injected failure")
    return fake_summary(run)


def exit_on_run_0(run):
    if run.index == 0:
        os._exit(3)  # the worker process dies without a word, as after a segfault
    time.sleep(0.2)  # runs 1..3 are still in flight when run 0 kills the pool
    return fake_summary(run)


def preloaded_module_seen(run):
    """A run function whose figure says whether its worker had imported ``colorsys`` before the run (a
    module nothing else of a worker imports): its ``preload`` asks for it."""
    return {"status": "ok", "reason": "", "object_position_error_rms_m": float("colorsys" in sys.modules)}


preloaded_module_seen.preload = ("colorsys",)


def test_local_workers_import_the_run_functions_preload_as_they_start():
    result = run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1,2,3"]), jobs=2, run_function=preloaded_module_seen)
    assert [r["object_position_error_rms_m"] for r in result.rows] == [1.0] * 4


def test_a_bad_run_stops_the_workers_started_before_the_validation():
    """The local workers start before the runs are validated (their imports overlap it): a bad run is
    still bad input, and no worker outlives the error."""
    import multiprocessing

    before = set(multiprocessing.active_children())
    with pytest.raises(ScenarioError, match="simulation.duration"):
        run_sweep(LIFT, SweepGrid.parse(["simulation.duration=0.1,-1"]), jobs=2, run_function=fake_summary)
    left = set(multiprocessing.active_children()) - before
    for child in left:  # terminated, or killed after 5 s: gone once the system has reaped it
        child.join(timeout=10.0)
    assert [child for child in left if child.is_alive()] == []


def test_exception_in_a_run_becomes_a_row():
    result = run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1,2"]), executor=SerialExecutor(), run_function=raise_on_run_1)
    assert [r["status"] for r in result.rows] == ["ok", "error", "ok"]
    assert result.rows[1]["reason"] == "RuntimeError: injected failure"
    assert [r["object_position_error_rms_m"] for r in result.rows] == [0.0, None, 2e-3]


def test_a_dead_worker_loses_only_its_own_run():
    """Run 0 kills its worker each time: it is retried once, alone, and is then an error row naming both
    deaths; every other run, in flight on the broken pool or not started, keeps its own result."""
    result = run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1,2,3,4,5,6,7"]), jobs=2, run_function=exit_on_run_0)
    assert [r["run"] for r in result.rows] == list(range(8))
    assert result.rows[0]["status"] == "error" and result.rows[0]["reason"].startswith("the run's worker process died twice")
    assert result.rows[0]["reason"].count("exited with code 3") == 2
    assert [r["status"] for r in result.rows[1:]] == ["ok"] * 7
    assert [r["object_position_error_rms_m"] for r in result.rows[1:]] == [k * 1e-3 for k in range(1, 8)]
    assert 0 in dict(result.retried) and "BrokenProcessPool" not in str(result.to_dict())


def test_interrupt_keeps_finished_rows(tmp_path):
    seen = []

    def stop_after_three(row):
        seen.append(row["run"])
        if len(seen) == 3:
            raise KeyboardInterrupt

    with pytest.raises(SweepInterrupted) as info:
        run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1,2,3,4,5"]), jobs=1, run_function=fake_summary,
                  on_row=stop_after_three, out=tmp_path, save_interval_s=3600.0)  # only the final save writes
    assert [r["run"] for r in info.value.result.rows] == [0, 1, 2] and info.value.result.runs == 6
    document = json.loads((tmp_path / "sweep.json").read_text())
    assert [r["run"] for r in document["rows"]] == [0, 1, 2] and document["complete"] is False
    assert len((tmp_path / "sweep.csv").read_text().splitlines()) == 1 + 3


def test_cli_interrupt_exits_130_and_keeps_rows(monkeypatch, capsys, tmp_path):
    def interrupt_at_run_2(run):
        if run.index == 2:
            raise KeyboardInterrupt
        return fake_summary(run)

    monkeypatch.setattr(cli.sweep, "worker_function", lambda: interrupt_at_run_2)
    args = ["sweep", str(LIFT), "--grid", "simulation.seed=0,1,2,3,4", "--jobs", "1", "--out", str(tmp_path), "-q"]
    assert cli.main(args) == 130
    err = capsys.readouterr().err
    assert err.splitlines() == [f"coopctrl: interrupted: 2 of 5 runs finished, kept in {tmp_path}"]
    assert [r["run"] for r in json.loads((tmp_path / "sweep.json").read_text())["rows"]] == [0, 1]


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups, SIGINT and /proc")
def test_ctrl_c_on_a_process_pool(tmp_path):
    """A real SIGINT to the whole process group, as a terminal's Ctrl-C, once the first row is saved:
    exit 130, no traceback, the finished rows on disk, and no worker process left behind."""
    out = tmp_path / "sweep"
    env = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    gains = ",".join(str(k) for k in range(10, 50))  # 40 runs: far from done when interrupted
    command = [sys.executable, "-m", "coopctrl", "sweep", str(LIFT), "--grid", f"controllers.followers.force_ki={gains}",
               "--set", "simulation.duration=0.5", "--jobs", "2", "--out", str(out), "-q"]
    proc = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while not (out / "sweep.json").exists() and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.05)
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 130, err
    assert "Traceback" not in err and err.startswith("coopctrl: interrupted: ") and f"kept in {out}" in err
    document = json.loads((out / "sweep.json").read_text())
    assert 1 <= document["finished"] < 40 and document["complete"] is False
    assert all(row["status"] == "ok" for row in document["rows"])
    assert _live_members(proc.pid) == []  # no worker left running


def _live_members(pgid: int, patience_s: float = 30.0) -> list[int]:
    """Processes of group ``pgid`` that are not zombies (read from /proc; exited workers may take a
    moment to be reaped, and without an init that reaps, a zombie would stay)."""
    from pathlib import Path

    deadline = time.monotonic() + patience_s
    while True:
        live = []
        for stat in Path("/proc").glob("[0-9]*/stat"):
            try:
                fields = stat.read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue  # exited meanwhile
            if int(fields[2]) == pgid and fields[0] != "Z":  # fields after the name: state, ppid, pgrp
                live.append(int(stat.parent.name))
        if not live or time.monotonic() > deadline:
            return live
        time.sleep(0.05)


def test_progress_bar_counts_finished_runs(capsys):
    run_sweep(LIFT, SweepGrid.parse(["simulation.seed=0,1,2"]), jobs=1, run_function=raise_on_run_1, progress=True)
    err = capsys.readouterr().err
    assert "3/3" in err and "failed=1" in err


# ---------------------------------------------------------------------- size of a grid (issue 22)
def test_a_huge_grid_is_counted_and_refused_before_expansion(monkeypatch, capsys):
    """Issue 22: a sweep of 1e8 grid points expanded and validated every combination (2.5 GiB after
    12 s). The count is the product of the axis lengths, checked when the grid is built."""
    from coopctrl.sweep.grid import MAX_RUNS

    def never(self):
        raise AssertionError("the grid was expanded")

    monkeypatch.setattr(SweepGrid, "combinations", never)
    axes = [f"controllers.followers.force_ki={','.join(str(k) for k in range(100))}",
            f"simulation.seed={','.join(str(k) for k in range(100))}",
            f"load_distribution.squeeze={','.join(str(k) for k in range(100))}",
            f"controllers.followers.force_kp={','.join(str(k / 100) for k in range(100))}"]
    args = ["sweep", str(LIFT)] + [a for axis in axes for a in ("--grid", axis)]
    assert cli.main(args) == 2
    err = capsys.readouterr().err
    assert f"at most {MAX_RUNS} runs in one sweep; this grid has 100 x 100 x 100 x 100 = 100000000 runs" in err
    assert len(err.splitlines()) == 1
    with pytest.raises(GridError, match="at most 10000 values on one axis"):
        SweepGrid.from_mapping({"simulation.seed": range(MAX_RUNS + 1)})
    assert len(SweepGrid.from_mapping({"simulation.seed": range(100), "simulation.substeps": range(1, 101)})) == MAX_RUNS
