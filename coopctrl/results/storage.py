"""Saving and loading a :class:`~coopctrl.results.SimulationResult` (npz, csv, json), atomically."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from coopctrl.io.atomic import atomic_write
from coopctrl.results.signals import pose_names, signals, wrench_names  # noqa: F401 (API)

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: Array fields stored in ``result.npz`` (``None`` fields are left out).
ARRAY_FIELDS = (
    "t", "x", "tau", "Y0", "Y0_nominal", "F_measured", "F_commanded", "F_external", "F_internal",
    "squeeze", "squeeze_desired", "tau_max", "qp_iterations", "qp_active_rows", "qp_solve_time_s", "energy", "kinetic_energy",
)
#: Scalar and dict fields stored as JSON in the ``meta`` entry of ``result.npz``.
META_FIELDS = (
    "scenario", "space", "status", "reason", "model", "integrator", "step_s", "control_period_s",
    "duration_s", "wall_time_s", "energy_conserving", "leader", "followers",
)


def csv_columns(result: "SimulationResult") -> tuple[list[str], np.ndarray]:
    """Header names ``"name [unit]"`` and the (N, columns) table written to ``result.csv``:
    time, then every signal of :func:`coopctrl.results.signals.signals` (named and numbered as
    documented there)."""
    n = result.t.shape[0]
    table = signals(result)
    names = ["t [s]"] + [f"{name} [{unit}]" for name, unit, _ in table]
    blocks = [result.t[:, None]] + [values[:, None] for _, _, values in table]
    return names, np.hstack(blocks) if n else np.zeros((0, len(names)))


def save_result(result: "SimulationResult", directory: str | Path) -> list[Path]:
    """Write ``result.npz``, ``result.csv`` and ``summary.json`` into ``directory``, each atomically."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []

    arrays = {name: getattr(result, name) for name in ARRAY_FIELDS if getattr(result, name) is not None}
    arrays["qp_status"] = np.array(result.qp_status, dtype=str)
    arrays["qp_binding"] = np.array(result.qp_binding, dtype=str)
    arrays["events_t"] = np.array([e[0] for e in result.events], dtype=float)
    arrays["events_kind"] = np.array([e[1] for e in result.events], dtype=str)
    arrays["events_message"] = np.array([e[2] for e in result.events], dtype=str)
    from coopctrl.results.summary import json_safe

    meta = json_safe({name: getattr(result, name) for name in META_FIELDS})
    meta["_nan"] = [name for name in META_FIELDS if isinstance(getattr(result, name), float) and meta[name] is None]
    arrays["meta"] = np.array(json.dumps(meta))
    path = directory / "result.npz"
    with atomic_write(path, "wb") as f:
        np.savez_compressed(f, **arrays)
    written.append(path)

    names, table = csv_columns(result)
    path = directory / "result.csv"
    with atomic_write(path, "w") as f:
        np.savetxt(f, table, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    written.append(path)

    path = directory / "summary.json"
    with atomic_write(path, "w") as f:
        json.dump(result.summary(), f, indent=2, allow_nan=False)
        f.write("\n")
    written.append(path)
    return written


def load_result(directory: str | Path) -> "SimulationResult":
    """Read the ``result.npz`` written by :func:`save_result`."""
    from coopctrl.results.simulation_result import SimulationResult

    with np.load(Path(directory) / "result.npz", allow_pickle=False) as data:
        meta = json.loads(str(data["meta"]))
        for name in meta.pop("_nan", []):
            meta[name] = float("nan")
        kwargs = {name: data[name] for name in ARRAY_FIELDS if name in data.files}
        kwargs["qp_status"] = [str(s) for s in data["qp_status"]]
        if "qp_binding" in data.files:  # results saved before it was recorded have none
            kwargs["qp_binding"] = [str(s) for s in data["qp_binding"]]
        kwargs["events"] = list(zip(data["events_t"].tolist(), data["events_kind"].tolist(), data["events_message"].tolist()))
    return SimulationResult(**kwargs, **meta)
