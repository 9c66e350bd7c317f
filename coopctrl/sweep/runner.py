"""``run_sweep``: validate every run, execute them on an executor, collect one row per run.

Guarantees:

- Nothing runs unless every combination's scenario is valid (:func:`~coopctrl.sweep.plan.plan_sweep`).
  Local workers start while the runs are validated (their imports overlap it); a bad run terminates them
  before the error propagates.
- A failed run (divergence, infeasible QP, any exception) is a row with its status and reason; it
  never loses the other rows. If a worker process of a local pool dies (SIGKILL, a crash, the
  out-of-memory killer), the pool's runs that had not started go to a fresh pool, and each run that had
  started is retried once, alone, in a fresh worker (:mod:`coopctrl.sweep.lost_worker`): the run whose
  worker dies again is an ``error`` row naming both deaths, the others keep their results. The result
  lists the retried runs (:attr:`SweepResult.retried`). On an executor the sweep did not make (a Dask
  cluster, a caller's pool) a lost run is an ``error`` row naming the executor's exception.
- Rows are ordered by run index, whatever the executor and the order of completion.
- With ``out``, ``sweep.csv`` and ``sweep.json`` are rewritten atomically as rows finish (at most
  every ``save_interval_s``) and once more at the end. On Ctrl-C (or an exception from ``on_row``)
  the finished rows are saved before the interruption propagates, as :class:`SweepInterrupted`.
"""

from __future__ import annotations

import os
import sys
import time
from concurrent.futures import FIRST_COMPLETED, BrokenExecutor, CancelledError, Executor, Future, wait
from pathlib import Path
from typing import Any, Callable, Mapping

from coopctrl.io.console import OutputWriteError
from coopctrl.sweep import reuse
from coopctrl.sweep.errors import SweepError, SweepInterrupted
from coopctrl.sweep.executors import LocalProcessPool, SerialExecutor, make_executor
from coopctrl.sweep.lost_worker import exit_cause
from coopctrl.sweep.grid import SweepGrid
from coopctrl.sweep.plan import SweepPlan, SweepRun, plan_sweep
from coopctrl.sweep.results import SweepResult, make_row
from coopctrl.sweep.worker import RunFunction, execute_run, simulate_run


#: Seconds a local worker gets beyond twice the run timeout (and its run function's start-up allowance,
#: :data:`~coopctrl.sweep.worker.STARTUP_ALLOWANCE_S` for the simulation) before the sweep stops it from
#: outside (a run stuck where the worker's own alarm cannot reach it, e.g. inside a C library); see
#: :func:`run_sweep`.
BACKSTOP_GRACE_S = 30.0


def backstop_s(run_function: RunFunction, run_timeout_s: float) -> float:
    """Seconds after which the sweep stops a run from outside: ``allowance + 2 run_timeout_s +
    BACKSTOP_GRACE_S``, where ``allowance`` is the run function's ``start_up_allowance_s`` (0 without a
    start-up phase). The sweep cannot see when a worker's start-up ends, so it waits for both."""
    allowance = float(getattr(run_function, "start_up_allowance_s", 0.0) or 0.0)
    return allowance + 2.0 * run_timeout_s + BACKSTOP_GRACE_S


def _lost_row(run: SweepRun, exc: BaseException) -> dict[str, Any]:
    """The row of a run whose future failed outside the run function (a worker process died, a
    task could not be pickled, the cluster lost it)."""
    return make_row(run.index, run.columns, "error", f"{type(exc).__name__}: {exc}", None, None)


class _Collector:
    """The rows so far, and their periodic atomic saving."""

    def __init__(self, plan: SweepPlan, out: Path | None, save_interval_s: float):
        self.plan = plan
        self.out = out
        self.save_interval_s = save_interval_s
        self.rows: dict[int, dict[str, Any]] = {}
        self._saved_at = -float("inf")
        self.retried: dict[int, str] = {}  # run index -> how its first worker died

    def result(self) -> SweepResult:
        p = self.plan
        return SweepResult(p.name, p.source, p.grid, p.sets, tuple(self.rows.values()), len(p.runs),
                           tuple(sorted(self.retried.items())))

    def add(self, row: dict[str, Any]) -> None:
        self.rows[row["run"]] = row
        if self.out is not None and time.monotonic() - self._saved_at >= self.save_interval_s:
            self.save()

    def save(self) -> SweepResult:
        result = self.result()
        if self.out is not None:
            result.save(self.out)
            self._saved_at = time.monotonic()
        return result


def _failed(exc: BaseException) -> Future:
    """A future that failed with ``exc`` (a run that could not be submitted)."""
    future: Future = Future()
    future.set_exception(exc)
    return future


def _row_of(future: Future, run: SweepRun) -> dict[str, Any]:
    try:
        return future.result()
    except (Exception, CancelledError) as exc:  # noqa: BLE001 - a lost run is a row, not a lost sweep
        return _lost_row(run, exc)


def run_sweep(
    scenario_path: str | Path | None,
    grid: SweepGrid,
    *,
    sets: Mapping[str, Any] | None = None,
    executor: Executor | None = None,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    on_row: Callable[[dict[str, Any]], None] | None = None,
    out: str | Path | None = None,
    run_function: RunFunction = simulate_run,
    save_interval_s: float = 1.0,
    run_timeout_s: float | None = None,
) -> SweepResult:
    """Run the Cartesian product of ``grid`` over a scenario; one row per run.

    Args:
        scenario_path: Scenario ``.toml`` file, or ``None`` for the built-in default scene.
        grid: The swept axes (:meth:`SweepGrid.parse` of ``--grid`` arguments).
        sets: Fixed overrides applied to every run (``--set``), ``{path: value}``.
        executor: Any :class:`concurrent.futures.Executor`; it is left open. ``None``: one made by
            :func:`~coopctrl.sweep.executors.make_executor` from ``jobs`` and ``scheduler`` (and
            shut down at the end).
        jobs: Local workers (1: in this process; default ``os.cpu_count()``, at most one per run).
        scheduler: Address of a Dask scheduler instead of local workers.
        progress: Show a tqdm progress bar on stderr, advanced as runs finish.
        on_row: Called in this process with each row as its run finishes (completion order).
        out: Directory for ``sweep.csv`` and ``sweep.json`` (created; rewritten as rows finish).
        run_function: Module-level function ``SweepRun -> summary dict`` executed for each run (a
            process pool pickles it by name); :func:`~coopctrl.sweep.worker.simulate_run` simulates.
        save_interval_s: Least time between two saves while running [s].
        run_timeout_s: Wall time after which a run is stopped and becomes a ``timeout`` row [s]
            (``None``: no limit), counted from the run's first tick: the worker's start-up (imports, the
            compiled kernels, building the scene) is not the run's time and has its own allowance
            (:data:`~coopctrl.sweep.worker.STARTUP_ALLOWANCE_S`; see :mod:`coopctrl.sweep.worker`).
            Applies to local workers and ``jobs = 1``, not on a Dask cluster. The worker stops its own
            run (an alarm). A run that does not answer it (stuck inside a C library) is stopped from
            outside :func:`backstop_s` after its worker took it: the pool's workers are terminated, that
            run is a ``timeout`` row and the other runs in flight start again on a fresh pool.

    Returns:
        The :class:`SweepResult`, rows by run index.

    Raises:
        ScenarioError, GridError: Bad input, before anything runs.
        SweepInterrupted: Ctrl-C (``KeyboardInterrupt``) during the sweep; its ``result`` holds the
            finished rows, already saved into ``out``.
        OutputWriteError: the system refused to write ``out`` (a full disk): the sweep stops its workers;
            the exception's ``partial`` is the :class:`SweepResult` of the rows finished so far.
    """
    if executor is not None and (jobs is not None or scheduler is not None):
        raise ValueError("run_sweep: give either an executor or jobs/scheduler, not both")
    if run_timeout_s is not None and not (run_timeout_s > 0 and run_timeout_s < float("inf")):
        raise SweepError(f"--run-timeout = {run_timeout_s!r} is invalid: expected a finite number of seconds > 0")
    owned = executor is None
    preload = tuple(getattr(run_function, "preload", ()) or ())
    if owned and scheduler is None and jobs is None:
        jobs = os.cpu_count() or 1
    if owned and isinstance(jobs, int) and jobs > len(grid):
        jobs = len(grid)  # no idle workers to start (len(grid): the runs, counted without expanding them)
    if owned and scheduler is None and isinstance(jobs, int) and not isinstance(jobs, bool) and jobs > 1:
        # local workers start now: their imports overlap the validation of every run below (a bad run stops them)
        executor = make_executor(jobs, None, preload=preload).start()
    try:
        plan = plan_sweep(scenario_path, grid, sets)
    except BaseException:
        if owned and executor is not None:
            executor.interrupt()
        raise
    if owned and executor is None:
        executor = make_executor(jobs, scheduler, preload=preload)
    # Serial: submit one run at a time so that rows stream. Otherwise keep every worker busy with one
    # more run queued each; an executor of unknown size gets every run at once.
    workers = getattr(executor, "workers", None)
    limit = 1 if isinstance(executor, SerialExecutor) else (2 * workers if workers else len(plan.runs))
    collector = _Collector(plan, None if out is None else Path(out), save_interval_s)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=len(plan.runs), desc=plan.name, unit="run", file=sys.stderr, mininterval=0.2)
    queue = iter(plan.runs)
    pending: dict[Future, SweepRun] = {}
    interrupted = False
    # the outside stop of a stuck run: on a pool this function owns (it may replace it)
    backstop = run_timeout_s is not None and owned and isinstance(executor, LocalProcessPool)
    started: dict[Future, float] = {}  # when each pending run was first seen running [s, monotonic]
    # a lost worker (see lost_worker): runs to resubmit, runs to retry alone, the retries' own pools
    recover = owned and isinstance(executor, LocalProcessPool)
    resubmit: list[SweepRun] = []
    retries: list[SweepRun] = []
    alone: dict[Future, LocalProcessPool] = {}
    pool_of: dict[Future, Executor] = {}
    losses: dict[int, int] = {}  # run index -> times it was lost with a broken pool
    broken: dict[Executor, tuple[set[int], str]] = {}  # each replaced pool: its started runs, how its worker died

    def submit(pool, run: SweepRun) -> Future:
        if recover and isinstance(pool, LocalProcessPool):  # its own pools: marked, to recover from a lost worker
            future = pool.submit_run(run_function, run, run_timeout_s)
        else:
            future = pool.submit(execute_run, run_function, run, run_timeout_s)
        pool_of[future] = pool
        return future

    def deliver(row: dict[str, Any]) -> None:
        collector.add(row)
        if bar is not None:
            bar.update(1)
            bar.set_postfix(failed=sum(r["status"] != "ok" for r in collector.rows.values()), refresh=False)
        if on_row is not None:
            on_row(row)

    def replace_broken(pool) -> None:
        """``pool`` lost a worker: note which of its runs had started, stop it, and make a fresh pool."""
        nonlocal executor
        if pool in broken:
            return
        marks = pool.marks.started() if getattr(pool, "marks", None) is not None else set()
        broken[pool] = (marks, exit_cause(pool.exit_codes()))
        pool.interrupt()
        if pool is executor:
            executor = make_executor(jobs, scheduler, preload=preload)

    def lost(future: Future, run: SweepRun) -> None:
        """A run of an owned local pool failed because a worker died: resubmit it, retry it alone, or (lost
        in its own retry, or lost too often) make it an ``error`` row."""
        pool = pool_of.get(future)
        own = alone.pop(future, None)
        if own is not None:  # its retry, alone in a fresh worker, died too: the run is the cause
            second = exit_cause(own.exit_codes())
            own.interrupt()
            deliver(make_row(run.index, run.columns, "error",
                             f"the run's worker process died twice: a worker of its pool "
                             f"{collector.retried.get(run.index, 'died')}, then its retry's own worker {second} (a "
                             "crash, the out-of-memory killer or a signal; the other runs are unaffected)", None, None))
            return
        replace_broken(pool)
        marks, cause = broken.get(pool, (set(), "died"))
        losses[run.index] = losses.get(run.index, 0) + 1
        if run.index in marks or losses[run.index] >= 2:  # it may be the cause: once more, alone
            collector.retried[run.index] = cause
            retries.append(run)
        else:  # never started: the next pool takes it
            resubmit.append(run)

    try:
        while True:
            while resubmit or len(pending) - len(alone) < limit:
                run = resubmit.pop(0) if resubmit else next(queue, None)
                if run is None:
                    break
                try:
                    future = submit(executor, run)
                except BrokenExecutor as exc:  # a worker process died: the runs it held come back through
                    if not owned:              # their futures; the rest go to a fresh pool
                        future = _failed(exc)
                    else:
                        if recover:
                            replace_broken(executor)
                        else:
                            executor.shutdown(wait=False, cancel_futures=True)
                            executor = make_executor(jobs, scheduler, preload=preload)
                        future = submit(executor, run)
                pending[future] = run
            if retries and not alone:  # one retry at a time, each in a fresh worker of its own
                run = retries.pop(0)
                own = LocalProcessPool(1, preload)
                future = submit(own, run)
                alone[future] = own
                pending[future] = run
            if not pending:
                break
            done, _ = wait(pending, timeout=1.0 if backstop else None, return_when=FIRST_COMPLETED)
            for future in sorted(done, key=lambda f: pending[f].index):
                started.pop(future, None)
                run = pending.pop(future)
                if recover and not future.cancelled() and isinstance(future.exception(), BrokenExecutor):
                    lost(future, run)
                    pool_of.pop(future, None)
                    continue
                own = alone.pop(future, None)
                if own is not None:
                    own.interrupt()
                pool_of.pop(future, None)
                deliver(_row_of(future, run))
            if backstop and not done:
                now = time.monotonic()
                for future in pending:
                    if future not in started and future.running():
                        started[future] = now
                limit_s = backstop_s(run_function, run_timeout_s)
                overdue = [f for f in pending if now - started.get(f, now) > limit_s]
                if overdue:  # stop the pools from outside; the others in flight start again on fresh ones
                    executor.interrupt()
                    for future in sorted(overdue, key=lambda f: pending[f].index):
                        run = pending.pop(future)
                        own = alone.pop(future, None)
                        if own is not None:
                            own.interrupt()
                        deliver(make_row(run.index, run.columns, "timeout",
                                         f"run stopped by the sweep {limit_s:g} s after its worker took it: it did not answer "
                                         f"its run timeout of {run_timeout_s:g} s (--run-timeout)", None,
                                         now - started[future]))
                    redo = [pending.pop(future) for future in sorted(pending, key=lambda f: pending[f].index)
                            if future not in alone]
                    started.clear()
                    executor = make_executor(jobs, scheduler, preload=preload)
                    for run in redo:
                        pending[submit(executor, run)] = run
    except BaseException as exc:
        interrupted = True
        for future, run in list(pending.items()):  # rows that finished but were not collected yet
            if future.done() and not future.cancelled() and future.exception() is None and run.index not in collector.rows:
                collector.rows[run.index] = future.result()
            future.cancel()
        for own in alone.values():
            own.interrupt()
        if owned:  # a caller's executor is theirs to stop; its queued runs were cancelled above
            stop = getattr(executor, "interrupt", None)
            if stop is not None:
                stop()
            else:
                executor.shutdown(wait=False, cancel_futures=True)
        if bar is not None:
            bar.close()
            bar = None
        try:
            partial = collector.save()
        except OutputWriteError as write_error:  # the system refused the output (a full disk): say so, with the rows
            write_error.partial = collector.result()
            raise write_error from None
        if isinstance(exc, OutputWriteError):
            exc.partial = partial
        if isinstance(exc, KeyboardInterrupt) and not isinstance(exc, SweepInterrupted):
            raise SweepInterrupted(partial) from None
        raise
    finally:
        if bar is not None:
            bar.close()
        if owned and not interrupted:
            if isinstance(executor, LocalProcessPool):  # every row is in and the workers are idle: stop them
                executor.interrupt()  # rather than wait for each to tear down its interpreter (about 1 s under load)
            else:
                executor.shutdown(wait=True)
        if isinstance(executor, SerialExecutor):  # the runs' loops were built in this thread: free them
            reuse.clear()
    try:
        return collector.save()
    except OutputWriteError as write_error:
        write_error.partial = collector.result()
        raise
