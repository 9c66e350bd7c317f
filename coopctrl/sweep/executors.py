"""Where the runs execute: any :class:`concurrent.futures.Executor`, made by :func:`make_executor`.

- ``jobs = 1``: :class:`SerialExecutor`, in this process, one run at a time (no start-up cost; the
  easiest to debug).
- ``jobs > 1`` (default ``os.cpu_count()``): :class:`LocalProcessPool`, a process pool. Workers are
  started with ``spawn``: a fresh interpreter inherits no threads or locks from this process (which
  may hold compiler, BLAS, tqdm or Dask threads, and ``fork`` with threads can deadlock), and it behaves
  the same on Linux, macOS and Windows. A worker's start-up costs about 0.85 s (imports, the compiled
  core's shared libraries loaded), paid once per worker; ``forkserver`` measured the same. It is
  not a run's time: a run's timeout and wall time start at its first tick (:mod:`coopctrl.sweep.worker`).
  :func:`~coopctrl.sweep.runner.run_sweep` starts the workers (:meth:`LocalProcessPool.start`) before it
  validates the runs, and each imports the run function's modules (its ``preload``) as it starts, so that
  the two overlap; a bad run stops them before the sweep reports it.
  Workers ignore SIGINT: Ctrl-C reaches the sweep, which stops them itself. Workers die with the sweep:
  on Linux the kernel sends them SIGKILL when their parent dies (``prctl(PR_SET_PDEATHSIG)``, which also
  covers a SIGKILL of the sweep); elsewhere a watchdog thread in each worker exits when its parent
  process is gone (polled every :data:`PARENT_POLL_S`).
- ``scheduler = ADDRESS``: :class:`DaskExecutor`, the runs go to a Dask cluster (the optional extra
  ``distributed``: ``pip install 'coopctrl[distributed]'``).

The runner uses two optional attributes of these executors: ``workers`` (how many runs execute at
once) and ``interrupt()`` (stop now, dropping queued and running runs).
"""

from __future__ import annotations

import ctypes
import ctypes.util
import importlib
import multiprocessing
import os
import signal
import sys
import threading
from concurrent.futures import Executor, Future, ProcessPoolExecutor

from coopctrl.errors import interruption_in
from coopctrl.sweep.errors import MissingExtra, SchedulerError, SweepError

#: Seconds to wait for a Dask scheduler before giving up.
CONNECT_TIMEOUT_S = 10.0
#: Seconds between two checks of a worker's watchdog that its parent is alive (non-Linux systems).
PARENT_POLL_S = 1.0
#: ``PR_SET_PDEATHSIG`` of ``<linux/prctl.h>``.
_PR_SET_PDEATHSIG = 1


class SerialExecutor(Executor):
    """Run each call in this process when it is submitted; the returned future is already done.

    An exception of the call is stored in its future; ``KeyboardInterrupt`` and ``SystemExit``
    propagate from :meth:`submit` (Ctrl-C stops the sweep at once).
    """

    workers = 1

    def __init__(self) -> None:
        self._shutdown = False

    def submit(self, fn, /, *args, **kwargs) -> Future:  # noqa: D102 - Executor API
        if self._shutdown:
            raise RuntimeError("cannot schedule new futures after shutdown")
        future: Future = Future()
        future.set_running_or_notify_cancel()
        try:
            result = fn(*args, **kwargs)
        except Exception as exc:  # noqa: BLE001 - delivered through the future, as any executor does
            stop = interruption_in(exc)
            if stop is not None:  # Ctrl-C wrapped by a library: still Ctrl-C
                raise stop from None
            future.set_exception(exc)
        else:
            future.set_result(result)
        return future

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:  # noqa: D102
        self._shutdown = True

    def interrupt(self) -> None:
        """Nothing runs in the background."""
        self._shutdown = True


def _die_with_parent(parent_pid: int) -> None:
    """Make this worker end when the process ``parent_pid`` ends, however it ends (SIGKILL included)."""
    armed = False
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
            armed = libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0) == 0
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent_pid:  # the parent died before the request above was armed
        os._exit(1)
    if not armed:
        def watch() -> None:
            while True:
                threading.Event().wait(PARENT_POLL_S)
                if os.getppid() != parent_pid:
                    os._exit(1)

        threading.Thread(target=watch, name="coopctrl-parent-watchdog", daemon=True).start()


def _init_worker(parent_pid: int, preload: tuple[str, ...] = ()) -> None:
    """Worker initializer: ignore SIGINT (Ctrl-C in a terminal signals the whole process group; only the
    sweep acts on it), restore the default SIGTERM, die with the sweep's process, then import the modules
    ``preload`` names. A module that fails to import is left to the run that needs it, which reports the
    error as its row."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent(parent_pid)
    for name in preload:
        try:
            importlib.import_module(name)
        except Exception:  # noqa: BLE001 - the run meets it again and makes it its row
            pass


class LocalProcessPool(ProcessPoolExecutor):
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``jobs`` spawned workers that ignore SIGINT
    and die with this process; each imports the modules ``preload`` names as it starts."""

    def __init__(self, jobs: int, preload: tuple[str, ...] = ()):
        super().__init__(max_workers=jobs, mp_context=multiprocessing.get_context("spawn"), initializer=_init_worker,
                         initargs=(os.getpid(), tuple(preload)))
        self.workers = jobs
        self.marks = None  # the RunMarks of submit_run, made at its first call

    def submit_run(self, run_function, run, timeout_s: float | None = None) -> Future:
        """Submit one run of a sweep, marked while it executes
        (:func:`~coopctrl.sweep.lost_worker.execute_marked`): if a worker dies, :attr:`marks` tells which
        runs had started."""
        from coopctrl.sweep.lost_worker import RunMarks, execute_marked

        if self.marks is None:
            self.marks = RunMarks()
        return self.submit(execute_marked, str(self.marks.folder), run_function, run, timeout_s)

    def exit_codes(self, patience_s: float = 5.0) -> list[int | None]:
        """The exit codes of the pool's worker processes (``None`` for one still running after ``patience_s``
        [s]). Called once the pool is broken: a dead worker's pipe reads as closed a moment before the system
        lets its exit code be read (more than a second on a loaded machine), and the pool stops the other workers
        itself."""
        processes = list((getattr(self, "_processes", None) or {}).values())
        for process in processes:
            process.join(timeout=patience_s)
        return [process.exitcode for process in processes]

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:  # noqa: D102
        super().shutdown(wait=wait, cancel_futures=cancel_futures)
        if self.marks is not None and wait:
            self.marks.remove()

    def start(self) -> "LocalProcessPool":
        """Start the workers now, rather than at the first run (they import and initialise while this
        process does other work, such as validating the runs); returns the pool."""
        self.submit(int)  # the pool starts every worker at its first task
        return self

    def interrupt(self) -> None:
        """Drop the queued runs and terminate the workers (their running runs are lost; finished
        ones were already delivered)."""
        processes = list((getattr(self, "_processes", None) or {}).values())  # private, stable since 3.2
        self.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            if process.is_alive():
                process.terminate()
        for process in processes:
            process.join(timeout=5.0)
            if process.is_alive():  # still starting up (importing), or slow to act on SIGTERM on a busy machine
                process.kill()
                process.join(timeout=5.0)
        if self.marks is not None:
            self.marks.remove()


def _close_half_made_client(exc: BaseException, client_type: type) -> None:
    """Close the ``Client`` whose constructor raised ``exc`` (found in the traceback's frames).

    After some failures (a malformed address) ``distributed`` leaves that client half-open; its
    ``__del__`` later waits 2 s for a stopped event loop and prints a traceback.
    """
    tb = exc.__traceback__
    while tb is not None:
        candidate = tb.tb_frame.f_locals.get("self")
        if isinstance(candidate, client_type):
            try:
                candidate.close(timeout=1)
            except Exception:  # noqa: BLE001 - best effort on an already failed client
                pass
            try:  # whatever close() managed: its __del__ must not try again (a 20 s wait and a traceback)
                candidate.status = "closed"
                candidate._loop_runner.stop()  # private; best effort
            except Exception:  # noqa: BLE001
                pass
            return
        tb = tb.tb_next


class DaskExecutor(Executor):
    """Runs on a Dask cluster through :meth:`distributed.Client.get_executor`.

    Args:
        address: The scheduler's address, e.g. ``tcp://scheduler.example:8786``.
        timeout_s: Seconds to wait for the connection.

    Raises:
        MissingExtra: ``distributed`` is not installed.
        SchedulerError: No Dask scheduler answers at ``address`` within ``timeout_s`` (nothing listens,
            the address is malformed, or something else answers, e.g. a web server).
    """

    def __init__(self, address: str, timeout_s: float = CONNECT_TIMEOUT_S):
        try:
            import distributed
        except ImportError:
            raise MissingExtra("--scheduler (running a sweep on a Dask cluster)", "distributed", "distributed") from None
        self.address = address
        try:
            self.client = distributed.Client(address, timeout=timeout_s, set_as_default=False)
        except Exception as exc:  # noqa: BLE001 - refused, timed out, malformed, or a peer that is no scheduler
            _close_half_made_client(exc, distributed.Client)
            detail = " ".join(str(exc).split()) or type(exc).__name__
            if not isinstance(exc, (OSError, TimeoutError, ValueError, TypeError)):
                detail = f"something answered there, but not a Dask scheduler: {type(exc).__name__}: {detail}"
            raise SchedulerError(address, detail) from None
        self._executor = self.client.get_executor(pure=False)  # every run is a new task, never deduplicated
        self.workers = max(1, sum(self.client.nthreads().values()))

    def submit(self, fn, /, *args, **kwargs) -> Future:  # noqa: D102 - Executor API
        return self._executor.submit(fn, *args, **kwargs)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:  # noqa: D102
        self._executor.shutdown(wait=wait and not cancel_futures)
        self.client.close()

    def interrupt(self) -> None:
        """Cancel the queued and running tasks and disconnect (the cluster itself keeps running)."""
        self.shutdown(wait=False, cancel_futures=True)


def make_executor(jobs: int | None = None, scheduler: str | None = None, *, timeout_s: float = CONNECT_TIMEOUT_S,
                  preload: tuple[str, ...] = ()) -> Executor:
    """The executor of a sweep: serial for ``jobs = 1``, a local process pool of ``jobs`` workers
    (default ``os.cpu_count()``) that import the modules ``preload`` names as they start, or a Dask
    cluster when ``scheduler`` is given.

    Raises:
        SweepError: ``jobs < 1``, or both ``jobs`` and ``scheduler``.
        MissingExtra, SchedulerError: See :class:`DaskExecutor`.
    """
    if scheduler is not None:
        if jobs is not None:
            raise SweepError(f"--jobs {jobs} and --scheduler {scheduler!r} exclude each other: "
                             "the cluster's workers run the sweep; give one of them")
        return DaskExecutor(scheduler, timeout_s)
    if jobs is None:
        jobs = os.cpu_count() or 1
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise SweepError(f"--jobs = {jobs!r} is invalid: expected an integer >= 1 (1 runs in this process)")
    return SerialExecutor() if jobs == 1 else LocalProcessPool(jobs, preload)
