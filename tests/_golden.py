"""Golden records of the shipped scenes: what the closed loop writes, kept as test data, so that a change of the
compiled core (the numba kernels moving to the C++ core, docs/core.md) is checked against the records of the code
before it.

A record is the run of one shipped scene (``scenarios/NAME.toml``, optionally with overrides: another integrator
family), over its whole duration, sampled every :data:`EVERY` ticks: the plant state ``x``, the joint torques
``tau`` [N m], the measured and the commanded contact wrenches ``F_measured``, ``F_commanded`` [N, N m] and the
squeeze [N]. ``tests/test_golden_records.py`` runs the cases again and compares; ``python tests/_golden.py``
writes the files (``tests/golden/NAME.npz``), only when a change is meant to change the numbers.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

#: The record's folder.
FOLDER = Path(__file__).resolve().parent / "golden"

#: Ticks between two kept samples.
EVERY = 25

#: The signals kept, by their names in :class:`~coopctrl.results.SimulationResult`.
SIGNALS = ("x", "tau", "F_measured", "F_commanded", "squeeze")

SCENES = sorted(p.stem for p in (Path(__file__).resolve().parent.parent / "scenarios").glob("*.toml"))

#: Each integrator family on the carry and on the planar lift (the shipped scenes all use rk4): name ->
#: (scene, overrides).
VARIANTS = {
    f"{scene}@{integrator}": (scene, {"simulation.integrator": integrator})
    for scene in ("spatial_two_puma_carry", "planar_two_arm_lift")
    for integrator in ("euler", "symplectic_euler", "implicit_midpoint", "rk45", "trbdf2")
}

#: Every case: the shipped scenes as they are, then the variants.
CASES = {**{name: (name, {}) for name in SCENES}, **VARIANTS}


def run_case(name: str) -> dict[str, np.ndarray]:
    """The sampled record of the case ``name`` (:data:`CASES`), and its status."""
    import coopctrl
    from coopctrl.simulator import simulate

    scene, overrides = CASES[name]
    result = simulate(coopctrl.load_scenario(scene, overrides or None), node_poses=False)
    ticks = np.arange(0, len(result.t), EVERY)
    record = {key: np.asarray(getattr(result, key), dtype=float)[ticks] for key in SIGNALS}
    record["t"] = np.asarray(result.t, dtype=float)[ticks]
    record["status"] = np.array(result.status)
    return record


def path_of(name: str) -> Path:
    return FOLDER / f"{name.replace('@', '__')}.npz"


def write(names) -> None:
    FOLDER.mkdir(exist_ok=True)
    for name in names:
        record = run_case(name)
        np.savez_compressed(path_of(name), **record)
        print(f"{name}: {record['status']}, {len(record['t'])} samples")


if __name__ == "__main__":
    write(sys.argv[1:] or list(CASES))
