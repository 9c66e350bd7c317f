"""The first run of a kind says what it does: one line on stderr before compiling, a ticker on a terminal.

The first run of a kind of kernels on a machine (:class:`coopctrl.loop.startup.KernelKind`: planar or
spatial, explicit or implicit integrators) compiles them for tens of seconds before its first tick;
later runs load them from the cache. ``coopctrl run`` and ``coopctrl sweep`` ask
:func:`coopctrl.loop.startup.is_cold` before any long work and, for a cold kind, print one line on
stderr::

    coopctrl: compiling the spatial closed-loop kernels (explicit integrators: rk4) for this machine:
    about 45 s once; later runs load them from ~/.cache/coopctrl/numba/coopctrl-0123456789abcdef

(on one line), with the estimate of :data:`COMPILE_S` times this machine's factor (:func:`machine_factor`:
how much longer its earlier first runs took than those figures, kept in :data:`TIMES_FILE`). On a terminal
(stderr is a TTY) an elapsed-time ticker follows on the next line until the kernels are ready
(:func:`coopctrl.loop.startup.listening`), then is erased; nothing else is written when stderr is not a
terminal. A warm run prints nothing.
"""

from __future__ import annotations

import math
import statistics
import sys
import threading
import time
from pathlib import Path
from typing import Iterable

from coopctrl.cli._core import PROG
from coopctrl.io.console import visible

#: Start-up of the first ``coopctrl run`` of a kind [s]: ``(on an empty cache, once another kind has been
#: compiled)``, on the project's 2-core machine class at a load average of about 1. Measured on 2026-12-02
#: with ``benchmarks/bench_startup.py`` (one run each, load 0.9): planar-explicit on an empty cache 59 s
#: (``--scene planar_two_arm_lift``) and spatial-explicit 88 s (the carry); spatial-explicit after the
#: planar kind 64 s more, planar-explicit after the spatial kind 34 s more. An implicit kind after its
#: explicit one took 33 s more while it also recompiled the tick (``run_ticks``); the tick now takes the
#: plan in slots of one type for every family (``coopctrl.integrators.compiled.plan_slots``) and a new family
#: compiles only its advance stage: measured side by side in one session on a busier machine, 34.8 s more
#: against 66.5 s before (0.52x), so about 20 s here (0.52 x 33 s = 17 s, rounded up); the error-controlled
#: kinds (rk23/rk45, trbdf2) are taken as the implicit one (not measured alone). Derived, not measured alone:
#: a non-explicit kind on an empty cache (its explicit kind's figure plus that increment). A second kind
#: compiles only what the first did not (the QP solver, the frames and the shared kernels are cached once).
#: Under load the wall times grow two to six times: the figures are estimates, said as such.
COMPILE_S = {
    "planar-explicit": (59.0, 34.0),
    "spatial-explicit": (88.0, 64.0),
    "planar-implicit": (79.0, 20.0),
    "spatial-implicit": (108.0, 20.0),
    "planar-embedded": (79.0, 20.0),
    "spatial-embedded": (108.0, 20.0),
    "planar-trbdf2": (79.0, 20.0),
    "spatial-trbdf2": (108.0, 20.0),
}

#: How often the ticker redraws [s].
TICK_S = 1.0

#: The file, in the kernel cache's base folder (the parent of ``coopctrl-<digest>``,
#: :func:`plants.numba_cache.keyed_directory`: it outlives a change of the kernels), that keeps this
#: machine's latest first runs, one line each: ``<kind> <estimate s> <measured s>``, the estimate from
#: :data:`COMPILE_S` alone, the measure from the notice to the end of the run's start-up (:func:`record_first_run`).
TIMES_FILE = "coopctrl-first-runs.txt"
#: Lines of :data:`TIMES_FILE` kept (the latest).
TIMES_KEPT = 8
#: Least numba compiling [s] in a first run for its time to be kept: a kind that its stamp calls cold
#: while its compiled files are in the cache compiles nothing, and its time says nothing of a compile
#: (a real first run compiles for tens of seconds).
LEAST_COMPILE_S = 5.0
#: Bounds of :func:`machine_factor` [-]: a factor beyond them says more about the runs kept than the machine.
FACTOR_RANGE = (0.25, 8.0)


def machine_factor(times_file) -> float:
    """How many times longer this machine's first runs took than :data:`COMPILE_S` says: the median of
    ``measured / estimate`` over the lines of ``times_file`` (:data:`TIMES_FILE`), within
    :data:`FACTOR_RANGE`; 1 when the file is missing or holds no valid line."""
    ratios = [ratio for _, ratio in _kept(times_file)]
    if not ratios:
        return 1.0
    low, high = FACTOR_RANGE
    return min(max(statistics.median(ratios), low), high)


#: Most bytes of :data:`TIMES_FILE` read (its :data:`TIMES_KEPT` lines take about 300): a file grown or
#: replaced by something else costs no more than this to read.
TIMES_READ_BYTES = 65536


def _kept(times_file) -> list[tuple[str, float]]:
    """The valid lines ``<kind> <estimate s> <measured s>`` among the first :data:`TIMES_READ_BYTES` of
    ``times_file``, each with its ratio ``measured / estimate`` (finite, positive); none when it cannot be read."""
    try:
        with open(times_file, "rb") as f:
            text = f.read(TIMES_READ_BYTES).decode("utf-8", errors="replace")
    except OSError:
        return []
    kept = []
    for line in text.splitlines():
        try:
            _, estimate, measured = (float(v) if i else v for i, v in enumerate(line.split()))
        except ValueError:
            continue
        if estimate > 0.0 and measured > 0.0 and math.isfinite(measured / estimate):
            kept.append((line, measured / estimate))
    return kept


def record_first_run(times_file, kind_name: str, estimate_s_: float, measured_s: float) -> None:
    """Add ``<kind_name> <estimate_s_> <measured_s>`` to ``times_file`` (:data:`TIMES_FILE`), keeping the
    latest :data:`TIMES_KEPT` lines; the file is replaced whole. A file that cannot be written keeps nothing
    (the next notice then uses the figures as they are)."""
    from coopctrl.io.atomic import write_text_if_possible

    lines = [line for line, _ in _kept(times_file)]  # the valid ones: a damaged file mends itself
    lines = [*lines, f"{kind_name} {estimate_s_:.1f} {measured_s:.1f}"][-TIMES_KEPT:]
    write_text_if_possible(times_file, "\n".join(lines) + "\n")


def estimate_s(kinds, warm_kinds=(), factor: float = 1.0) -> float:
    """About how long compiling the cold ``kinds`` takes [s] (:data:`COMPILE_S`): the first at its
    empty-cache figure when no kind is warm (``warm_kinds``), every other at its second figure; the sum
    times ``factor`` (this machine's: :func:`machine_factor`)."""
    total = 0.0
    for i, kind in enumerate(kinds):
        alone, after = COMPILE_S[kind.name]
        total += alone if i == 0 and not warm_kinds else after
    return total * factor


def about(seconds: float) -> str:
    """``"about 45 s"``, or ``"about 2 min"`` from 100 s on (an estimate: whole seconds, whole minutes)."""
    if seconds < 100:
        return f"about {max(round(seconds), 1)} s"
    return f"about {round(seconds / 60.0)} min"


def notice_line(kinds: dict, directory: Path, warm_kinds=(), factor: float = 1.0) -> str:
    """The one line of the notice: ``kinds`` maps each cold :class:`~coopctrl.loop.startup.KernelKind`
    to the integrator names that need it; ``factor``: this machine's (:func:`machine_factor`)."""
    from coopctrl.loop.startup import FAMILIES, SPACES

    order = sorted(kinds, key=lambda k: (SPACES.index(k.space), FAMILIES.index(k.family)))
    what = " and ".join(f"the {k.space} closed-loop kernels ({k.family} integrators: {', '.join(sorted(kinds[k]))})"
                        for k in order)
    return (f"{PROG}: compiling {what} for this machine: {about(estimate_s(order, warm_kinds, factor))} once; "
            f"later runs load them from {visible(directory)}")


class CompileNotice:
    """The notice of a first run (:func:`announce`): its ticker, stopped by :meth:`close` or by the end
    of the run's start-up; and, for a notice of one kind with ``timing = (kind, estimate [s], times_file)``,
    the time from the notice to the end of that kind's start-up, added to ``times_file`` (:func:`record_first_run`)
    when numba compiled for at least :data:`LEAST_COMPILE_S` meanwhile (its ``numba:compile`` events,
    :mod:`numba.core.event`)."""

    def __init__(self, stream, ticker: bool, timing=None) -> None:
        self._stream = stream
        self._stop = threading.Event()
        self._thread = None
        self._width = 0
        self._listening = None
        self._timing = timing
        self._began = time.monotonic()
        self._compiling = None
        if timing is not None:
            from numba.core import event

            self._compiling = event.TimingListener()  # the outermost compiles' time (nested ones not twice)
            event.register("numba:compile", self._compiling)
        if ticker or timing is not None:
            from coopctrl.loop.startup import listening

            self._listening = listening(self._ready)
            self._listening.__enter__()
        if ticker:
            self._thread = threading.Thread(target=self._tick, name="coopctrl-compile-ticker", daemon=True)
            self._thread.start()

    def _ready(self, kind, seconds: float) -> None:
        """A run's start-up ended (:func:`coopctrl.loop.startup.started`): the ticker stops; the time of a
        timed kind is kept."""
        self.stop_ticker()
        if self._timing is None or kind != self._timing[0]:
            return
        _, estimate, times_file = self._timing
        measured = time.monotonic() - self._began
        compiled = self._stop_timing()
        if compiled >= LEAST_COMPILE_S:
            record_first_run(times_file, kind.name, estimate, measured)

    def _stop_timing(self) -> float:
        """Stop listening to numba's compile events; the seconds they took (idempotent: 0 after the first call)."""
        self._timing = None
        if self._compiling is None:
            return 0.0
        from numba.core import event

        event.unregister("numba:compile", self._compiling)
        compiled = self._compiling.duration if self._compiling.done else 0.0
        self._compiling = None
        return compiled

    def _tick(self) -> None:
        began = time.monotonic()
        while not self._stop.wait(TICK_S):
            text = f"  compiling: {time.monotonic() - began:.0f} s"
            self._width = max(self._width, len(text))
            try:
                self._stream.write("\r" + text.ljust(self._width))
                self._stream.flush()
            except (OSError, ValueError):  # a closed or broken terminal: no ticker
                return

    def stop_ticker(self) -> None:
        """Stop the ticker and erase its line (idempotent)."""
        if self._thread is None:
            return
        self._stop.set()
        self._thread.join()
        self._thread = None
        if self._width:
            try:
                self._stream.write("\r" + " " * self._width + "\r")
                self._stream.flush()
            except (OSError, ValueError):
                pass

    def close(self) -> None:
        """Stop the ticker (if any), the timing (nothing is kept of a run that ended before its start-up did)
        and stop listening."""
        self.stop_ticker()
        self._stop_timing()
        if self._listening is not None:
            self._listening.__exit__(None, None, None)
            self._listening = None


def cold_kinds(scenarios: Iterable, directory: Path | None = None) -> dict:
    """The cold :class:`~coopctrl.loop.startup.KernelKind` of ``scenarios`` in the cache ``directory``
    (default: this tree's), each with the integrator names that need it (``{}``: all warm)."""
    from coopctrl.loop.startup import cache_directory, is_cold, kind_of

    needed: dict = {}
    for scenario in scenarios:
        needed.setdefault(kind_of(scenario), set()).add(scenario.simulation.integrator)
    directory = cache_directory() if directory is None else Path(directory)
    return {k: names for k, names in needed.items() if is_cold(k, directory)}


def announce(scenarios: Iterable, *, ticker: bool = True, stream=None,
             directory: Path | None = None, times_file: Path | None = None,
             keep_time: bool = True) -> CompileNotice | None:
    """Print the notice for the cold kinds among those of ``scenarios`` in the cache ``directory``
    (default: this tree's); ``None`` and nothing printed when all are warm. ``ticker``: draw the
    elapsed-time ticker when ``stream`` (default stderr) is a terminal. ``times_file``: this machine's first
    runs (:data:`TIMES_FILE`), which scale the estimate (:func:`machine_factor`) and keep this one's time
    (a notice of one kind; :class:`CompileNotice`); by default :data:`TIMES_FILE` in the cache's base
    folder when ``directory`` is the default, none when ``directory`` is given. ``keep_time=False``: read the
    file, keep nothing (a sweep: its workers compile, not this process)."""
    from coopctrl.loop.startup import FAMILIES, SPACES, KernelKind, cache_directory, is_cold

    stream = sys.stderr if stream is None else stream
    if directory is None:  # this tree's cache, coopctrl-<digest>, in the base folder that keeps the times
        directory = cache_directory()
        times_file = directory.parent / TIMES_FILE if times_file is None else times_file
    directory = Path(directory)
    cold = cold_kinds(scenarios, directory)
    if not cold:
        return None
    warm = [k for k in (KernelKind(s, f) for s in SPACES for f in FAMILIES) if not is_cold(k, directory)]
    factor = machine_factor(times_file) if times_file is not None else 1.0
    print(notice_line(cold, directory, warm, factor), file=stream, flush=True)
    try:
        tty = stream.isatty()
    except (AttributeError, ValueError):
        tty = False
    timing = None
    if keep_time and times_file is not None and len(cold) == 1:
        (kind,) = cold
        timing = (kind, estimate_s([kind], warm), times_file)
    return CompileNotice(stream, ticker and tty, timing)


def sweep_scenarios(scenario_path, grid, sets) -> list:
    """The scenarios of a sweep that differ in their kind of kernels: the scenario with ``sets`` and each
    value of the grid's ``simulation.integrator`` and ``scene.space`` axes (those that do not validate
    are left out: the sweep reports them)."""
    import itertools

    from coopctrl.scenario.loader import load_scenario, parse_override_path

    kinds_paths = [tuple(parse_override_path(p)) for p in ("simulation.integrator", "scene.space")]
    axes = [a for a in grid.axes if tuple(parse_override_path(a.path)) in kinds_paths]
    out = []
    for values in itertools.product(*(a.values for a in axes)):
        try:
            out.append(load_scenario(scenario_path, {**dict(sets), **{a.path: v for a, v in zip(axes, values)}}))
        except Exception:  # noqa: BLE001 - any bad input is the sweep's to report (before it runs anything)
            continue
    return out


def announce_sweep(scenario_path, grid, sets, run_function, *, ticker: bool = True) -> CompileNotice | None:
    """:func:`announce` for a sweep whose runs call ``run_function``: only the simulator's
    (:func:`coopctrl.sweep.worker.simulate_run`) compiles; and only once every run is valid
    (:func:`coopctrl.sweep.plan.plan_sweep` raises on bad input before the notice, as the sweep would:
    checked again only when a kind is cold, whose compile dwarfs it)."""
    from coopctrl.sweep.worker import simulate_run

    if run_function is not simulate_run:
        return None
    scenarios = sweep_scenarios(scenario_path, grid, sets)
    if not cold_kinds(scenarios):
        return None
    from coopctrl.sweep.plan import plan_sweep

    plan_sweep(scenario_path, grid, sets)
    return announce(scenarios, ticker=ticker, keep_time=False)
