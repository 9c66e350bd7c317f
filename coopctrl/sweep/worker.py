"""What a worker does with one run: :func:`simulate_run` (the default run function) and
:func:`execute_run`, which turns whatever the run function does, an exception included, into a row.

Both are module-level functions so that a process pool or a Dask cluster can pickle them by name.
"""

from __future__ import annotations

import time
from typing import Any, Callable

from coopctrl.errors import DivergenceError, InfeasibleLoad
from coopctrl.sweep.plan import SweepRun
from coopctrl.sweep.results import make_row

#: A run function: takes a :class:`SweepRun`, returns a summary dict with at least ``status`` and
#: ``reason`` (:meth:`~coopctrl.results.SimulationResult.summary`), or raises.
RunFunction = Callable[[SweepRun], dict]


def simulate_run(run: SweepRun) -> dict[str, Any]:
    """Load the run's scenario (its data with the overrides), simulate it and return the summary."""
    from coopctrl.simulator import simulate

    return simulate(run.scenario()).summary()


def execute_run(run_function: RunFunction, run: SweepRun) -> dict[str, Any]:
    """Call ``run_function(run)`` and return the run's row (:func:`~coopctrl.sweep.results.make_row`).

    The status is the summary's own; a :class:`~coopctrl.errors.DivergenceError` raised by the run
    is ``diverged``, an :class:`~coopctrl.errors.InfeasibleLoad` ``qp_failed``, and any other
    exception ``error`` with the reason ``"<ExceptionType>: <message>"``. Only ``KeyboardInterrupt``
    and ``SystemExit`` go through. ``wall_time_s`` is the whole call [s].
    """
    start = time.perf_counter()
    summary: dict[str, Any] | None = None
    try:
        summary = run_function(run)
        status, reason = summary.get("status", "ok"), summary.get("reason", "")
    except DivergenceError as exc:
        status, reason = "diverged", str(exc)
    except InfeasibleLoad as exc:
        status, reason = "qp_failed", str(exc)
    except Exception as exc:  # noqa: BLE001 - one failed run must never lose the other rows
        summary, status, reason = None, "error", f"{type(exc).__name__}: {exc}"
    return make_row(run.index, run.columns, status, reason, summary, time.perf_counter() - start)
