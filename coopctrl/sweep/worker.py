"""What a worker does with one run: :func:`simulate_run` (the default run function) and
:func:`execute_run`, which turns whatever the run function does, an exception included, into a row.

Both are module-level functions so that a process pool or a Dask cluster can pickle them by name.
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from coopctrl.errors import DivergenceError, InfeasibleLoad, interruption_in
from coopctrl.sweep.plan import SweepRun
from coopctrl.sweep.results import make_row

#: A run function: takes a :class:`SweepRun`, returns a summary dict with at least ``status`` and
#: ``reason`` (:meth:`~coopctrl.results.SimulationResult.summary`), or raises.
RunFunction = Callable[[SweepRun], dict]


def simulate_run(run: SweepRun) -> dict[str, Any]:
    """Load the run's scenario (its data with the overrides), simulate it and return the summary."""
    from coopctrl.simulator import simulate

    return simulate(run.scenario()).summary()


class RunTimeout(Exception):
    """A run went past the sweep's ``--run-timeout``; its row has status ``timeout``."""


@contextmanager
def _deadline(timeout_s: float | None) -> Iterator[list[str]]:
    """Raise :class:`RunTimeout` in this thread after ``timeout_s`` seconds of wall time (SIGALRM).

    Only in a process's main thread on a POSIX system (a local worker, or the sweep's own process with
    ``jobs = 1``); elsewhere (a Dask worker's thread) the run has no deadline. The alarm interrupts
    Python code, i.e. the closed loop between two control ticks; the library calls inside one tick are
    guarded against non-termination on validated input. Yields a list that holds the timeout's message
    once it fired (the exception may surface wrapped, e.g. as numba's ``SystemError``).
    """
    fired: list[str] = []
    usable = (timeout_s is not None and hasattr(signal, "setitimer")
              and threading.current_thread() is threading.main_thread())
    if not usable:
        yield fired
        return

    def expire(signum, frame) -> None:
        fired.append(f"run stopped after the run timeout of {timeout_s:g} s (--run-timeout)")
        raise RunTimeout(fired[0])

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, timeout_s)
    try:
        yield fired
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


def execute_run(run_function: RunFunction, run: SweepRun, timeout_s: float | None = None) -> dict[str, Any]:
    """Call ``run_function(run)`` and return the run's row (:func:`~coopctrl.sweep.results.make_row`).

    The status is the summary's own; a :class:`~coopctrl.errors.DivergenceError` raised by the run
    is ``diverged``, an :class:`~coopctrl.errors.InfeasibleLoad` ``qp_failed``, a run still going after
    ``timeout_s`` seconds [s] ``timeout`` (see :func:`_deadline`), and any other exception ``error``
    with the reason ``"<ExceptionType>: <message>"``. Only ``KeyboardInterrupt`` and ``SystemExit`` go
    through. ``wall_time_s`` is the whole call [s].
    """
    start = time.perf_counter()
    summary: dict[str, Any] | None = None
    fired: list[str] = []
    try:
        with _deadline(timeout_s) as fired:
            summary = run_function(run)
        status, reason = summary.get("status", "ok"), summary.get("reason", "")
    except RunTimeout as exc:
        summary, status, reason = None, "timeout", str(exc)
    except Exception as exc:  # noqa: BLE001 - classified below
        stop = interruption_in(exc)
        if stop is not None:  # Ctrl-C wrapped by a library: still Ctrl-C
            raise stop from None
        if fired:  # the timeout, wrapped by the library it interrupted
            summary, status, reason = None, "timeout", fired[0]
        else:
            summary, status, reason = _failure(exc)
    return make_row(run.index, run.columns, status, reason, summary, time.perf_counter() - start)


def _failure(exc: Exception) -> tuple[None, str, str]:
    """The (summary, status, reason) of a run that raised ``exc``."""
    if isinstance(exc, DivergenceError):
        return None, "diverged", str(exc)
    if isinstance(exc, InfeasibleLoad):
        return None, "qp_failed", str(exc)
    return None, "error", f"{type(exc).__name__}: {exc}"  # one failed run must never lose the other rows
