"""A worker process of a local pool that dies during a run (SIGKILL, the out-of-memory killer, a crash).

:class:`~concurrent.futures.ProcessPoolExecutor` then fails every run it holds with ``BrokenProcessPool``,
the runs of the other workers and those not started yet included, and does not say whose worker died.
The sweep (:func:`~coopctrl.sweep.runner.run_sweep`) needs both answers:

- Which runs had started: each run of a local pool leaves a marker file, named after its index, in the
  pool's :class:`RunMarks` folder while it executes (:func:`execute_marked`). A lost run without a marker
  never started: it goes to a fresh pool as if nothing happened.
- Which of the started runs killed its worker: unknown from outside, so each started run is retried
  once, alone, in a fresh single-worker pool. A run whose worker dies there too is the cause; its row
  is an ``error`` naming both deaths (:func:`exit_cause`). The other runs keep their results.
"""

from __future__ import annotations

import os
import shutil
import signal
import tempfile
from pathlib import Path
from typing import Any, Iterable

from coopctrl.sweep.plan import SweepRun
from coopctrl.sweep.worker import RunFunction, execute_run


class RunMarks:
    """The folder where a pool's workers mark the runs they execute (one empty file per run, named after
    its index); a private temporary folder, removed by :meth:`remove`."""

    def __init__(self) -> None:
        self.folder = Path(tempfile.mkdtemp(prefix="coopctrl-sweep-runs."))

    def started(self) -> set[int]:
        """The indices of the runs whose execution had begun and not ended (the folder's entries; none
        when the folder cannot be read)."""
        try:
            return {int(name) for name in os.listdir(self.folder) if name.isdigit()}
        except OSError:
            return set()

    def remove(self) -> None:
        shutil.rmtree(self.folder, ignore_errors=True)


def execute_marked(folder: str, run_function: RunFunction, run: SweepRun, timeout_s: float | None = None) -> dict[str, Any]:
    """:func:`~coopctrl.sweep.worker.execute_run` with a marker ``folder/<run.index>`` for as long as the
    run executes (a worker that dies leaves it behind). A marker that cannot be written (a full disk) is
    skipped: the sweep then counts the run as not started, and bounds its losses otherwise."""
    marker = os.path.join(folder, str(run.index))
    try:
        with open(marker, "w"):
            pass
    except OSError:
        marker = None
    try:
        return execute_run(run_function, run, timeout_s)
    finally:
        if marker is not None:
            try:
                os.remove(marker)
            except OSError:
                pass


def exit_cause(exit_codes: Iterable[int | None]) -> str:
    """How a pool's worker died, from its processes' exit codes: ``"was killed by signal 9 (SIGKILL)"``,
    ``"exited with code 3"``, or ``"died"`` when no code says (the pool's own SIGTERM of the survivors
    is not a cause)."""
    causes = []
    for code in exit_codes:
        if code is None or code == 0 or code == -signal.SIGTERM:
            continue
        if code < 0:
            try:
                name = signal.Signals(-code).name
            except ValueError:
                name = "unknown signal"
            causes.append(f"was killed by signal {-code} ({name})")
        else:
            causes.append(f"exited with code {code}")
    return causes[0] if causes else "died"
