"""Run functions of a sweep whose worker process dies (tests/test_reliability_round4_io.py): the sweep's
workers import this module by name, so that these functions can be pickled.

Which run dies, and whether only once, comes from the environment that the test sets before the sweep
starts its workers (inherited by them): ``COOPCTRL_TEST_KILL_RUNS`` (run indices, comma-separated),
``COOPCTRL_TEST_KILL_ONCE_DIR`` (a folder: a run whose marker file is there was killed already), and
``COOPCTRL_TEST_KILL_SIMULATE`` (``1``: the other runs simulate for real, else a fake summary).
"""

from __future__ import annotations

import os
import signal
import time
from pathlib import Path


def _killed_runs() -> set[int]:
    return {int(k) for k in os.environ.get("COOPCTRL_TEST_KILL_RUNS", "").split(",") if k.strip()}


def fake_summary(run) -> dict:
    """A summary whose figure identifies the run (no simulation)."""
    time.sleep(0.05)  # a moment, so that the other worker's run is in flight when one worker dies
    return {"status": "ok", "reason": "", "object_position_error_rms_m": run.index * 1e-3, "simulated_time_s": 0.05}


def _finish(run) -> dict:
    if os.environ.get("COOPCTRL_TEST_KILL_SIMULATE") == "1":
        from coopctrl.sweep.worker import simulate_run

        return simulate_run(run)
    return fake_summary(run)


def kill_once(run) -> dict:
    """SIGKILL this worker the first time a run of ``COOPCTRL_TEST_KILL_RUNS`` executes (a marker file in
    ``COOPCTRL_TEST_KILL_ONCE_DIR`` remembers it), else finish the run."""
    if run.index in _killed_runs():
        marker = Path(os.environ["COOPCTRL_TEST_KILL_ONCE_DIR"]) / f"killed-{run.index}"
        if not marker.exists():
            marker.write_text(str(os.getpid()))
            os.kill(os.getpid(), signal.SIGKILL)
    return _finish(run)


def kill_always(run) -> dict:
    """SIGKILL this worker whenever a run of ``COOPCTRL_TEST_KILL_RUNS`` executes."""
    if run.index in _killed_runs():
        os.kill(os.getpid(), signal.SIGKILL)
    return _finish(run)
