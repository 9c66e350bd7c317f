"""Compile the closed loop's kernels into the kernel cache, on every core, before a distributed test run.

Each *task* is a short run (ten ticks) of a shipped scene of one space with one integrator, or through the
reference path (proxsuite): ``python tests/_warm_kernels.py SPACE OVERRIDE`` runs one, and its run compiles
(or loads) the kernels it needs, which the compiler's cache keeps (:mod:`plants.numba_cache`).
:func:`warm` runs the tasks of the spaces it is given, at most ``jobs`` processes at a time: first each
space's explicit run (it compiles the space's tick and plant kernels), then, once it is done, that space's
other tasks, which load those and compile only their own stages. ``tests/conftest.py`` calls it before the
whole suite when the cache lacks some kernels, so that the test workers load them rather than each compile
the same ones at the same time.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from typing import Callable

#: A shipped scene per space.
SCENES = {"planar": "planar_two_arm_lift", "spatial": "spatial_two_puma_carry"}
#: The first task of a space (the explicit family: its tick and plant kernels), then the others: an integrator
#: of each other family (coopctrl.loop.startup.family_of) and the reference path's QP backend.
FIRST = "simulation.integrator=rk4"
OTHERS = ("simulation.integrator=implicit_euler", "simulation.integrator=rk45", "simulation.integrator=trbdf2",
          "load_distribution.solver=proxsuite")
#: Each task's run [s]: 10 control periods of the scenes' 1 kHz.
DURATION = 0.01


def run(space: str, override: str) -> None:
    """Run :data:`SCENES` ``[space]`` with ``override`` (``"path=value"``) for :data:`DURATION`."""
    import coopctrl
    from coopctrl.simulator import simulate

    path, value = override.split("=", 1)
    simulate(coopctrl.load_scenario(SCENES[space], {path: value, "simulation.duration": DURATION}))


def warm(spaces, jobs: int = 2, timeout_s: float = 3600.0, say: Callable[[str], None] = print) -> bool:
    """Run the tasks of ``spaces`` (each a process, at most ``jobs`` at a time; a space's other tasks after its
    first), saying each one's end and time [s] through ``say``. A task still running after ``timeout_s`` [s]
    from the start is stopped. Returns True when every task exited 0 (a failure is said with its output)."""
    ready = [(space, FIRST) for space in spaces]
    running: dict = {}
    ok, t0 = True, time.monotonic()
    while ready or running:
        while ready and len(running) < jobs:
            task = ready.pop(0)
            child = subprocess.Popen([sys.executable, __file__, *task], stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, text=True, env=os.environ.copy())
            running[task] = (child, time.monotonic())
        time.sleep(0.2)
        for task, (child, started) in list(running.items()):
            late = time.monotonic() - t0 > timeout_s
            if child.poll() is None and not late:
                continue
            if late and child.poll() is None:
                child.kill()
            out = child.communicate()[0]
            del running[task]
            space, override = task
            if child.returncode == 0:
                say(f"  {space} {override}: {time.monotonic() - started:.0f} s")
            else:
                ok = False
                say(f"  {space} {override} failed (exit {child.returncode}); the tests compile what they need:\n{out}")
            if override == FIRST:
                ready[:0] = [(space, other) for other in OTHERS]  # the space unlocked last first: its tick is the larger
    return ok


if __name__ == "__main__":
    if len(sys.argv) != 3 or sys.argv[1] not in SCENES or "=" not in sys.argv[2]:
        sys.exit(f"usage: python {sys.argv[0]} {{{','.join(SCENES)}}} PATH=VALUE")
    run(sys.argv[1], sys.argv[2])
