"""A worker's built loops, reused across the runs of a sweep that differ only in the sensor noise seed.

Building a run's closed loop (the plant, the controllers, the compiled loop's arrays) and its initial
state costs about as much as the ticks of a short run. What a built
:class:`~coopctrl.closed_loop.ClosedLoop` takes as a run input is the initial state and its sensors'
noise streams (drawn at the start of every run from ``sensors.seed``, see
:meth:`ClosedLoop.run <coopctrl.closed_loop.ClosedLoop.run>`); everything else of the scenario is
built into it. So a worker keeps one built loop per :func:`loop_key` (the scenario with its seed set
to 0) and runs each seed on it with that seed's :class:`~coopctrl.sensors.SensorSuite`.
The row is then bit for bit the one of a fresh :func:`~coopctrl.simulator.simulate` of the same
scenario (``tests/test_sweep_reuse.py``). Any other difference, a grid over a gain, the duration, the
integrator or the start, is another key and builds its own loop.

Pre-flight (:mod:`coopctrl.analysis.preflight`) is not part of a sweep's run: a run that cannot be done
is that run's ``diverged``, ``qp_failed`` or ``error`` row (``coopctrl check`` checks one scene).

The cache lives in the thread (a Dask worker runs tasks in threads; a local worker or ``--jobs 1`` in
its main thread) and holds at most :data:`MAX_LOOPS` loops, the most recently used.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

#: Built loops a thread keeps (each holds its plant, its controllers and the compiled loop's work arrays).
MAX_LOOPS = 4


def loop_key(scenario):
    """What a built loop depends on: ``scenario`` with ``simulation.seed = 0`` (a hashable Scenario)."""
    return replace(scenario, simulation=replace(scenario.simulation, seed=0))


@dataclass
class _Built:
    """One built loop of a key: the loop, its start ``x0`` (``None``: let
    :func:`~coopctrl.simulator.run_result` meet the loaded start's failure itself)."""

    loop: Any
    x0: np.ndarray | None


_local = threading.local()
#: The scene kinds whose compiled kernels this process has loaded (:func:`prepare`).
_warmed: set[tuple] = set()
_warmed_lock = threading.Lock()


def kind(scenario) -> tuple:
    """What selects the compiled kernels' specialisation: the space, the arm models, the integrator, the
    QP solver, whether the controllers run and whether torque limits bind."""
    return (scenario.scene.space, tuple(a.model for a in scenario.arms), scenario.simulation.integrator,
            scenario.load_distribution.solver, scenario.controllers.enabled, scenario.load_distribution.torque_limits)


def _cache() -> "OrderedDict[Any, _Built]":
    cache = getattr(_local, "loops", None)
    if cache is None:
        cache = _local.loops = OrderedDict()
    return cache


def clear() -> None:
    """Forget this thread's built loops."""
    _cache().clear()


def _built(scenario) -> _Built:
    """The built loop of ``scenario``'s key in this thread, built now if new."""
    from coopctrl.errors import InfeasibleLoad
    from coopctrl.scenario import build
    from coopctrl.wiring import closed_loop

    key = loop_key(scenario)
    cache = _cache()
    entry = cache.get(key)
    if entry is not None:
        cache.move_to_end(key)
        return entry
    loop = closed_loop(key)
    try:
        x0 = build.initial_state(key)
    except InfeasibleLoad:
        x0 = None
    entry = cache[key] = _Built(loop, x0)
    while len(cache) > MAX_LOOPS:
        cache.popitem(last=False)
    return entry


def prepare(scenario, warm_up_failed: Callable[[Exception], None] | None = None) -> Callable[[], dict[str, Any]]:
    """Set up the run of ``scenario`` (a worker's start-up: build its loop or reuse the one built for its
    key) and return the run: a function of no arguments that runs it and returns its summary
    (:meth:`~coopctrl.results.SimulationResult.summary`).

    The first run of a scene :func:`kind` in this process is preceded by a run of one control period
    (outcome ignored) that loads (or compiles) the kind's kernels, so that the run itself is timed from
    its first tick. An exception of that short run goes to ``warm_up_failed`` (which may raise it: a
    timeout, Ctrl-C); the real run meets the same error and reports it."""
    from coopctrl.sensors import SensorSuite
    from coopctrl.simulator import run_result

    entry = _built(scenario)
    loop = entry.loop
    s = loop.sensors
    # the run inputs of this run; the rest of the built loop is the key's (a run starts from a fresh
    # loop state: its noise streams restart from sensors.seed, see ClosedLoop.run)
    loop.sensors = SensorSuite(s.joints.config, s.forces.config, s.object.config, scenario.simulation.seed)
    x0 = entry.x0
    k = kind(scenario)
    if x0 is not None and k not in _warmed:
        try:
            loop.run(x0, scenario.simulation.control_period)
        except BaseException as exc:  # noqa: BLE001 - handed to the caller
            if not isinstance(exc, Exception) or warm_up_failed is None:
                _forget(scenario)
                raise
            try:
                warm_up_failed(exc)
            except BaseException:
                _forget(scenario)
                raise
        with _warmed_lock:
            _warmed.add(k)

    def run() -> dict[str, Any]:
        try:
            return run_result(scenario, loop, None if x0 is None else x0.copy()).summary()
        except BaseException:  # a run stopped anywhere (a timeout, Ctrl-C, an error): build afresh next time
            _forget(scenario)
            raise

    return run


def _forget(scenario) -> None:
    """Drop the built loop of ``scenario``'s key from this thread's cache."""
    _cache().pop(loop_key(scenario), None)
