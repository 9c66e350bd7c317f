"""Compile the closed loop's kernels of one space, for every integrator family, into the kernel cache.

``python tests/_warm_kernels.py planar`` (or ``spatial``) runs ten ticks of a shipped scene of that space
with one integrator of each family (:data:`coopctrl.loop.startup.FAMILIES`), the compiled QP's and the
reference path's (proxsuite) tick, so that their kernels are compiled once and cached
(:mod:`plants.numba_cache`). ``tests/conftest.py`` runs one such process per space side by side before a
distributed run (``pytest -n``), so that the test workers load the kernels rather than each compile the
same ones at once. It prints what it ran and how long each took [s].
"""

from __future__ import annotations

import sys
import time

import coopctrl
from coopctrl.loop.startup import FAMILIES, SPACES
from coopctrl.simulator import simulate

#: A shipped scene per space.
SCENES = {"planar": "planar_two_arm_lift", "spatial": "spatial_two_puma_carry"}
#: An integrator per family (coopctrl.loop.startup.family_of).
INTEGRATORS = {"explicit": "rk4", "implicit": "implicit_euler", "embedded": "rk45", "trbdf2": "trbdf2"}
#: Ticks of each run [s]: 10 control periods of the scenes' 1 kHz.
DURATION = 0.01


def warm(space: str) -> None:
    """Run each family's integrator on :data:`SCENES` ``[space]`` for :data:`DURATION`, then the reference
    path's tick (proxsuite), printing each run's time [s]."""
    runs = [{"simulation.integrator": INTEGRATORS[family]} for family in FAMILIES]
    runs.append({"load_distribution.solver": "proxsuite"})
    for overrides in runs:
        t0 = time.perf_counter()
        simulate(coopctrl.load_scenario(SCENES[space], {**overrides, "simulation.duration": DURATION}))
        print(f"{space} {overrides}: {time.perf_counter() - t0:.1f} s", flush=True)


if __name__ == "__main__":
    if len(sys.argv) != 2 or sys.argv[1] not in SPACES:
        sys.exit(f"usage: python {sys.argv[0]} {{{','.join(SPACES)}}}")
    warm(sys.argv[1])
