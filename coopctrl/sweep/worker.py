"""What a worker does with one run: :func:`simulate_run` (the default run function) and
:func:`execute_run`, which turns whatever the run function does, an exception included, into a row.

Both are module-level functions so that a process pool or a Dask cluster can pickle them by name.

A run is timed from its first tick, not from the worker's start-up. A run function may declare a
start-up phase: it sets the attribute ``start_up_allowance_s`` [s] and does its set-up inside
:func:`start_up` (imports, building the scene). The start-up is then bounded by that allowance
(:data:`STARTUP_ALLOWANCE_S` for :func:`simulate_run`), and the run timeout and the row's ``wall_time_s`` count
from the end of the start-up. A fresh worker under load takes seconds to start (3.5 s measured: a 0.2 s run
became a ``timeout``); that is not the run's time. A run function without a start-up phase is timed from its
call.
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

#: Seconds a worker may take to start a run of :func:`simulate_run` before the run is stopped as a
#: ``timeout``: the imports (the compiled core is a shared library, loaded, never compiled) and the scene built,
#: under a second on a quiet machine, a few seconds under load; ten times the slowest seen. Only with a run
#: timeout; the run's own timeout starts after it.
STARTUP_ALLOWANCE_S = 60.0


class RunTimeout(Exception):
    """A run went past the sweep's ``--run-timeout`` (or its start-up past its allowance); its row has
    status ``timeout``."""


class _RunClock:
    """The clock of one run in :func:`execute_run`: its phase (``"start-up"`` or ``"run"``), when the run
    itself started [s, ``time.perf_counter``], and whether its alarm (SIGALRM) can be re-armed."""

    def __init__(self, timeout_s: float | None, allowance_s: float | None, alarm: bool):
        self.timeout_s = timeout_s
        self.allowance_s = STARTUP_ALLOWANCE_S if allowance_s is None else allowance_s
        self.alarm = alarm
        self.phase = "run"
        self.run_start = time.perf_counter()
        self.fired: list[str] = []

    def arm(self, seconds: float | None) -> None:
        if self.alarm and seconds is not None:
            signal.setitimer(signal.ITIMER_REAL, seconds)

    def expired(self) -> str:
        """The reason of a timeout in the current phase."""
        if self.phase == "start-up":
            return (f"the worker's start-up (imports, compiled kernels, building the scene) went past its allowance of "
                    f"{self.allowance_s:g} s; the run never started")
        return f"run stopped after the run timeout of {self.timeout_s:g} s (--run-timeout)"


_local = threading.local()


def current_phase() -> str | None:
    """``"start-up"`` or ``"run"`` inside :func:`execute_run` in this thread, else ``None``."""
    clock = getattr(_local, "clock", None)
    return None if clock is None else clock.phase


@contextmanager
def start_up() -> Iterator[None]:
    """The start-up of a run (see the module docstring): inside, the run's timeout is replaced by the run
    function's ``start_up_allowance_s``; on leaving, the run's clock (its timeout and ``wall_time_s``)
    starts. Outside :func:`execute_run` it does nothing."""
    clock = getattr(_local, "clock", None)
    if clock is None:
        yield
        return
    clock.phase = "start-up"
    clock.arm(clock.allowance_s)
    yield
    clock.phase = "run"
    clock.run_start = time.perf_counter()
    clock.arm(clock.timeout_s)


def _warm_up_failed(exc: Exception) -> None:
    """The kernels' warm-up run failed with ``exc``: a timeout or a Ctrl-C goes on; any other error is
    left to the real run, which meets it and reports it."""
    clock = getattr(_local, "clock", None)
    if (clock is not None and clock.fired) or interruption_in(exc) is not None:
        raise exc


def simulate_run(run: SweepRun) -> dict[str, Any]:
    """Load the run's scenario (its data with the overrides), simulate it and return the summary, the
    same as :func:`~coopctrl.simulator.simulate`'s. The imports, the scenario, its closed loop (built, or
    reused from an earlier run of this worker that differed only in the seed: :mod:`coopctrl.sweep.reuse`)
    and, once per scene kind, a one-period run that loads the compiled kernels are its start-up
    (:func:`start_up`); the run is timed from its first tick."""
    with start_up():
        from coopctrl.sweep import reuse

        go = reuse.prepare(run.scenario(), _warm_up_failed)
    return go()


simulate_run.start_up_allowance_s = STARTUP_ALLOWANCE_S
#: What a local worker of a sweep of :func:`simulate_run` imports as it starts, while the sweep validates its
#: runs (:class:`~coopctrl.sweep.executors.LocalProcessPool`).
simulate_run.preload = ("coopctrl.simulator",)


@contextmanager
def _deadline(clock: _RunClock) -> Iterator[list[str]]:
    """Raise :class:`RunTimeout` in this thread after ``clock.timeout_s`` seconds of wall time (SIGALRM),
    re-armed by :func:`start_up` (the start-up allowance, then the run timeout from the first tick).

    Only in a process's main thread on a POSIX system (a local worker, or the sweep's own process with
    ``jobs = 1``); elsewhere (a Dask worker's thread) the run has no deadline. The alarm interrupts
    Python code, i.e. the closed loop between two control ticks; the library calls inside one tick are
    guarded against non-termination on validated input. Yields a list that holds the timeout's message
    once it fired (the exception may surface wrapped, e.g. as the JIT compiler's ``SystemError``).
    """
    if not clock.alarm:
        yield clock.fired
        return

    def expire(signum, frame) -> None:
        clock.fired.append(clock.expired())
        raise RunTimeout(clock.fired[0])

    previous = signal.signal(signal.SIGALRM, expire)
    clock.arm(clock.timeout_s)
    try:
        yield clock.fired
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, previous)


def execute_run(run_function: RunFunction, run: SweepRun, timeout_s: float | None = None) -> dict[str, Any]:
    """Call ``run_function(run)`` and return the run's row (:func:`~coopctrl.sweep.results.make_row`).

    The status is the summary's own; a :class:`~coopctrl.errors.DivergenceError` raised by the run
    is ``diverged``, an :class:`~coopctrl.errors.InfeasibleLoad` ``qp_failed``, a run still going after
    ``timeout_s`` seconds [s] ``timeout`` (see :func:`_deadline`), and any other exception ``error``
    with the reason ``"<ExceptionType>: <message>"``. Only ``KeyboardInterrupt`` and ``SystemExit`` go
    through. ``wall_time_s`` [s] and the timeout count from the run's first tick: from the end of the run
    function's :func:`start_up` (bounded by its ``start_up_allowance_s``), else from its call.
    """
    alarm = (timeout_s is not None and hasattr(signal, "setitimer")
             and threading.current_thread() is threading.main_thread())
    clock = _RunClock(timeout_s, getattr(run_function, "start_up_allowance_s", None), alarm)
    summary: dict[str, Any] | None = None
    outer, _local.clock = getattr(_local, "clock", None), clock
    try:
        with _deadline(clock) as fired:
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
    finally:
        _local.clock = outer
    return make_row(run.index, run.columns, status, reason, summary, time.perf_counter() - clock.run_start)


def _failure(exc: Exception) -> tuple[None, str, str]:
    """The (summary, status, reason) of a run that raised ``exc``."""
    if isinstance(exc, DivergenceError):
        return None, "diverged", str(exc)
    if isinstance(exc, InfeasibleLoad):
        return None, "qp_failed", str(exc)
    return None, "error", f"{type(exc).__name__}: {exc}"  # one failed run must never lose the other rows
