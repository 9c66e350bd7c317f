"""Saving and loading a :class:`~coopctrl.results.SimulationResult` (npz, csv, json), atomically."""

from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from coopctrl.io.atomic import atomic_write

if TYPE_CHECKING:
    from coopctrl.results.simulation_result import SimulationResult

#: Array fields stored in ``result.npz`` (``None`` fields are left out).
ARRAY_FIELDS = (
    "t", "x", "tau", "Y0", "Y0_nominal", "F_measured", "F_commanded", "F_external", "F_internal",
    "squeeze", "squeeze_desired", "tau_max", "qp_iterations", "qp_solve_time_s", "energy", "kinetic_energy",
)
#: Scalar and dict fields stored as JSON in the ``meta`` entry of ``result.npz``.
META_FIELDS = (
    "scenario", "space", "status", "reason", "model", "integrator", "step_s", "control_period_s",
    "duration_s", "wall_time_s", "energy_conserving", "leader", "followers",
)


def pose_names(p: int) -> list[str]:
    """Coordinate names of a pose (MODEL.md §2)."""
    return ["x", "z", "theta"] if p == 3 else ["x", "y", "z", "psi", "theta", "phi"]


def wrench_names(p: int) -> list[str]:
    """Component names of a wrench."""
    return ["fx", "fz", "my"] if p == 3 else ["fx", "fy", "fz", "mx", "my", "mz"]


def csv_columns(result: "SimulationResult") -> tuple[list[str], np.ndarray]:
    """Header names and the (N, columns) table written to ``result.csv``."""
    r = result
    n, p, m = r.t.shape[0], r.pose_size, r.arms
    names, blocks = ["t"], [r.t[:, None]]
    names += [f"Y0_{c}" for c in pose_names(p)]
    blocks.append(r.Y0)
    names += [f"Y0_nominal_{c}" for c in pose_names(p)]
    blocks.append(r.Y0_nominal)
    for field in ("F_measured", "F_commanded", "F_external", "F_internal"):
        names += [f"{field}_{k + 1}_{c}" for k in range(m) for c in wrench_names(p)]
        blocks.append(getattr(r, field).reshape(n, m * p))
    names += [f"squeeze_{k}" for k in range(r.squeeze.shape[1])]
    blocks.append(r.squeeze)
    names += [f"tau_{j}" for j in range(r.tau.shape[1])]
    blocks.append(r.tau)
    for field in ("qp_iterations", "qp_solve_time_s", "energy"):
        value = getattr(r, field)
        if value is not None and value.shape[0] == n:
            names.append(field)
            blocks.append(value[:, None])
    return names, np.hstack(blocks) if n else np.zeros((0, len(names)))


def save_result(result: "SimulationResult", directory: str | Path) -> list[Path]:
    """Write ``result.npz``, ``result.csv`` and ``summary.json`` into ``directory``, each atomically."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []

    arrays = {name: getattr(result, name) for name in ARRAY_FIELDS if getattr(result, name) is not None}
    arrays["qp_status"] = np.array(result.qp_status, dtype=str)
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
        kwargs["events"] = list(zip(data["events_t"].tolist(), data["events_kind"].tolist(), data["events_message"].tolist()))
    return SimulationResult(**kwargs, **meta)
