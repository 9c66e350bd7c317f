"""A sweep times a run from its first tick, not from its worker's start-up (issue 21 item 8).

Under load a fresh worker took about 3.5 s to import and load the numba kernels, and a 0.2 s run with
``--run-timeout 3`` became a ``timeout``. The run functions here stand for a worker whose start-up is
slow (a seeded sleep inside :func:`~coopctrl.sweep.worker.start_up`); they run in this process
(``execute_run`` as ``--jobs 1`` calls it), so the alarm is the worker's own.
"""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest

from coopctrl.sweep import SweepGrid, execute_run, plan_sweep
from coopctrl.sweep import runner, worker

pytestmark = pytest.mark.skipif(not hasattr(signal, "setitimer"), reason="the run timeout is a POSIX alarm")

#: The slow start-up [s]: longer than the run timeout below, so that timing the run from the call
#: (the former behaviour) turns the run into a timeout whatever the machine's speed.
START_UP_S = 0.4 + 0.2 * float(np.random.default_rng(21).random())
RUN_TIMEOUT_S = 0.3


@pytest.fixture(scope="module")
def run():
    return plan_sweep(None, SweepGrid.parse(["simulation.seed=0"])).runs[0]


def _slow_start_up(run):
    """A quick run after a slow start-up; returns the time its run began [s, perf_counter]."""
    with worker.start_up():
        time.sleep(START_UP_S)
    began = time.perf_counter()
    return {"status": "ok", "reason": "", "began": began}


_slow_start_up.start_up_allowance_s = 30.0


def test_a_slow_start_up_does_not_time_out_a_short_run(run):
    began = []

    def call(r):
        summary = _slow_start_up(r)
        began.append(summary["began"])
        return summary

    call.start_up_allowance_s = _slow_start_up.start_up_allowance_s
    before = time.perf_counter()
    row = execute_run(call, run, RUN_TIMEOUT_S)
    total = time.perf_counter() - before
    assert row["status"] == "ok", row["reason"]
    assert began
    # the row's wall time is the run's, from the end of the start-up: the whole call minus a sleep of at
    # least START_UP_S bounds it (time.sleep sleeps at least that long), whatever the machine's speed
    assert 0.0 <= row["wall_time_s"] <= total - START_UP_S


def _stuck_start_up(run):
    with worker.start_up():
        while True:
            time.sleep(0.01)


_stuck_start_up.start_up_allowance_s = 0.2


def test_a_hung_start_up_is_stopped_by_its_allowance(run):
    row = execute_run(_stuck_start_up, run, 60.0)
    assert row["status"] == "timeout"
    assert "start-up" in row["reason"] and "allowance of 0.2 s" in row["reason"]


def _stuck_after_start_up(run):
    with worker.start_up():
        time.sleep(0.01)
    while True:
        time.sleep(0.01)


_stuck_after_start_up.start_up_allowance_s = 30.0


def test_the_run_itself_still_has_its_timeout(run):
    row = execute_run(_stuck_after_start_up, run, RUN_TIMEOUT_S)
    assert row["status"] == "timeout" and "--run-timeout" in row["reason"]


def test_simulate_run_loads_the_kernels_in_its_start_up(run, monkeypatch):
    """The default run function does its imports, the scenario, its loop and the kernels' warm-up inside
    the start-up (coopctrl.sweep.reuse.prepare), and simulates in the run phase (no simulation here:
    both are recorded, not run)."""
    from coopctrl.sweep import reuse

    phases = []

    def prepare(scenario, warm_up_failed=None):
        phases.append(("prepare", worker.current_phase()))
        return lambda: phases.append(("simulate", worker.current_phase())) or {"status": "ok", "reason": ""}

    monkeypatch.setattr(reuse, "prepare", prepare)
    row = execute_run(worker.simulate_run, run, 5.0)
    assert row["status"] == "ok"
    assert phases == [("prepare", "start-up"), ("simulate", "run")]
    assert worker.current_phase() is None  # outside a run


def test_the_outside_stop_waits_for_the_start_up_allowance_too():
    assert runner.backstop_s(worker.simulate_run, 3.0) == worker.STARTUP_ALLOWANCE_S + 6.0 + runner.BACKSTOP_GRACE_S
    assert runner.backstop_s(lambda r: {}, 3.0) == 6.0 + runner.BACKSTOP_GRACE_S  # no start-up phase declared
