"""The tick compiled in a second process while this one compiles the tick's stages (a first run of a kind).

A first run of a kind (:mod:`coopctrl.loop.startup`) compiles the tick's stages
(:func:`coopctrl.loop.kernel.tick_stages`) and then :func:`~coopctrl.loop.kernel.run_ticks`, one after the
other, on one core. ``run_ticks`` needs only the *types* of its arguments: a stage enters it as a numba
function type, fixed by the stage's signature, not by its machine code. So the run computes that signature
before compiling any stage (:func:`coopctrl.loop.kernel.tick_stages` with ``types_only=True``) and
:func:`start` hands it to a child process (this module run as ``python -m coopctrl.loop.compile_ahead``),
which compiles ``run_ticks`` (and the reference path's :func:`~coopctrl.loop.kernel.reference_step`) for it
into the kernel cache (:mod:`plants.numba_cache`), while the run compiles the stages. The run then waits for
the child (:meth:`Ahead.wait`) and loads the tick from the cache through numba's public
``Dispatcher.compile``, which reads the cache's index from disk.

``coopctrl run`` starts the child earlier still, before pre-flight
(:func:`coopctrl.loop.compiled.compile_tick_ahead`): pre-flight compiles its own kernels (inverse
kinematics, the QP, the torque model) on one core while the child compiles the tick, which shares none of
them, on the other; the run then claims that child.

Nothing depends on the child: if it cannot start, fails, or compiled another signature, the run compiles
the tick itself, as before (only the time is lost). The machine code is the same either way (LLVM is
deterministic; the records of every shipped scene are bit-identical). A child still running when this
process exits (one no run claimed: pre-flight refused the task, or the run was interrupted) is killed
(:func:`stop_all`).
"""

from __future__ import annotations

import atexit
import os
import pickle
import subprocess
import sys
from pathlib import Path

#: Seconds the run waits for the child at most before compiling the tick itself (it compiles in about a
#: minute on a slow 2-core machine; the limit only stops a hung child, which is then killed).
WAIT_TIMEOUT_S = 600.0

#: The functions of :mod:`coopctrl.loop.kernel` a child may compile, by name.
FUNCTIONS = ("run_ticks", "reference_step")


class Ahead:
    """A child process compiling kernel functions for given signatures (:func:`start`)."""

    def __init__(self, process: subprocess.Popen | None):
        self.process = process

    def wait(self, timeout_s: float = WAIT_TIMEOUT_S) -> bool:
        """Wait for the child [s at most]; True when it compiled every function it was given. A child
        still running after ``timeout_s`` is killed (the run then compiles what it needs itself)."""
        if self.process is None:
            return False
        try:
            self.process.wait(timeout=timeout_s)
        except BaseException:  # a hung child, or the run interrupted (Ctrl-C) while it waits: the child goes too
            self.stop()
            if sys.exc_info()[0] is not subprocess.TimeoutExpired:
                raise
        return self.process.returncode == 0

    def stop(self) -> None:
        """Kill the child if it still runs (the run was interrupted, or gave up waiting) and reap it."""
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
            self.process.wait()


def start(jobs: list[tuple[str, tuple]]) -> Ahead:
    """Start a child process that compiles each ``(name, signature)`` of ``jobs`` (``name`` among
    :data:`FUNCTIONS`; ``signature`` a tuple of numba types) into the kernel cache. A child that cannot
    start (no process, unpicklable types) is reported as such by :meth:`Ahead.wait` (False)."""
    for name, _ in jobs:
        if name not in FUNCTIONS:
            raise ValueError(f"compile_ahead.start: function {name!r} is invalid: expected one of {FUNCTIONS}")
    try:
        payload = pickle.dumps(jobs)
        top = str(Path(__file__).resolve().parent.parent.parent)  # the tree of this coopctrl (and its plants)
        env = {**os.environ, "PYTHONPATH": top + os.pathsep + os.environ.get("PYTHONPATH", "")}
        process = subprocess.Popen([sys.executable, "-m", "coopctrl.loop.compile_ahead"], stdin=subprocess.PIPE,
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=top)
        process.stdin.write(payload)
        process.stdin.close()
    except Exception:  # noqa: BLE001 - any failure only means the run compiles the tick itself
        return Ahead(None)
    _STARTED.append(process)
    return Ahead(process)


#: The children this process started (reaped ones are dropped by :func:`stop_all`).
_STARTED: list = []


@atexit.register
def stop_all() -> None:
    """Kill and reap every child this process started that still runs (at exit: none outlives the run)."""
    while _STARTED:
        Ahead(_STARTED.pop()).stop()


def _compile_from_stdin() -> None:
    """The child: compile each ``(name, signature)`` read (pickled) from stdin."""
    import coopctrl.loop.kernel as K

    jobs = pickle.loads(sys.stdin.buffer.read())
    for name, signature in jobs:
        if name not in FUNCTIONS:
            raise SystemExit(f"unknown function {name!r}")
        getattr(K, name).compile(signature)


if __name__ == "__main__":
    _compile_from_stdin()
