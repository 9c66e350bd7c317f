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
    "duration_s", "wall_time_s", "startup_s", "energy_conserving", "leader", "followers", "qp_active_constraints",
    "qp_time_s", "torque_saturated_ticks", "record_every", "tick_summary", "scenario_sha256",
    "integration_statistics",
)
#: The node (end-effector) poses are stored too (optional on reading: older results have none).
ARRAY_FIELDS = ARRAY_FIELDS + ("Y_nodes",)
#: A run in rotation charts stores the object's exact rotation (a quaternion per sample; optional on reading).
ARRAY_FIELDS = ARRAY_FIELDS + ("object_rotation",)
#: Array fields that every ``result.npz`` holds (the others are optional).
REQUIRED_ARRAYS = ARRAY_FIELDS[:11]
#: Entries of ``result.npz`` besides the array fields (the events, the QP's strings, the ``meta`` JSON).
TEXT_ENTRIES = ("qp_status", "events_t", "events_kind", "events_message", "meta")
#: The type each ``meta`` field must have when read back (``float`` fields may be ``None`` for NaN).
_META_TYPES = {
    "scenario": str, "space": str, "status": str, "reason": str, "model": dict, "integrator": str,
    "step_s": float, "control_period_s": float, "duration_s": float, "wall_time_s": float, "startup_s": float,
    "energy_conserving": bool, "leader": int, "followers": list, "qp_active_constraints": dict,
    "qp_time_s": float, "torque_saturated_ticks": int, "record_every": int, "tick_summary": (dict, type(None)),
    "scenario_sha256": str, "integration_statistics": (dict, type(None)), "_nan": list,
}
#: How to get a whole result again, appended to every message about a damaged ``result.npz``.
RERUN = "rerun `coopctrl run SCENARIO --out DIR` to write it again"


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
    """Write ``result.npz``, ``result.csv`` and ``summary.json`` into ``directory``, each atomically.

    A failure of the system (a full disk) is an :class:`~coopctrl.io.console.OutputWriteError` naming
    the file; the file is then left as it was."""
    from coopctrl.io.console import writing

    directory = Path(directory)
    with writing(str(directory)):
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
    with writing(str(path)), atomic_write(path, "wb") as f:
        np.savez_compressed(f, **arrays)
    written.append(path)

    names, table = csv_columns(result)
    path = directory / "result.csv"
    with writing(str(path)), atomic_write(path, "w") as f:
        np.savetxt(f, table, delimiter=",", header=",".join(names), comments="", fmt="%.10g")
    written.append(path)

    path = directory / "summary.json"
    with writing(str(path)), atomic_write(path, "w") as f:
        json.dump(result.summary(), f, indent=2, allow_nan=False)
        f.write("\n")
    written.append(path)
    return written


def load_result(directory: str | Path) -> "SimulationResult":
    """Read the ``result.npz`` written by :func:`save_result`, trusting nothing it claims.

    Raises:
        DamagedFileError: the file is truncated, empty, altered, has an unknown or missing entry, a
            header that claims more than the file holds, or arrays that do not fit together (exit 2;
            the message names the file and what is wrong).
        OSError: it cannot be opened (missing, a directory, no permission).
    """
    from coopctrl.io.npz_reader import DamagedFileError, read_npz
    from coopctrl.record_memory import OVERHEAD_FACTOR, available_memory_bytes
    from coopctrl.results.simulation_result import SimulationResult

    path = Path(directory) / "result.npz"
    optional = [name for name in ARRAY_FIELDS if name not in REQUIRED_ARRAYS] + ["qp_binding"]
    data = read_npz(path, REQUIRED_ARRAYS + TEXT_ENTRIES, optional,
                    max_bytes=available_memory_bytes() / OVERHEAD_FACTOR, fix=RERUN)

    def damaged(problem: str) -> DamagedFileError:
        return DamagedFileError(path, problem, RERUN)

    for name, value in data.items():
        text = name in ("qp_status", "qp_binding", "events_kind", "events_message", "meta")
        if text and value.dtype.kind != "U":
            raise damaged(f"entry {name!r} holds {value.dtype}, expected text")
        if not text and value.dtype.kind not in "fiub":
            raise damaged(f"entry {name!r} holds {value.dtype}, expected numbers")
    if data["meta"].shape != () or data["meta"].dtype.kind != "U":
        raise damaged("entry 'meta' is not one JSON text")
    try:
        meta = json.loads(str(data["meta"]))
    except ValueError as exc:
        raise damaged(f"entry 'meta' is not valid JSON ({' '.join(str(exc).split())})") from None
    if not isinstance(meta, dict):
        raise damaged("entry 'meta' is not a JSON object")
    for name in ("scenario", "space", "status"):
        if name not in meta:
            raise damaged(f"entry 'meta' has no {name!r}")
    for name, value in meta.items():
        want = _META_TYPES.get(name)
        if want is None:
            raise damaged(f"entry 'meta' has the unknown field {name!r}")
        if want is float:
            ok = value is None or (isinstance(value, (int, float)) and not isinstance(value, bool))
        elif want is int:
            ok = isinstance(value, int) and not isinstance(value, bool)
        else:
            ok = isinstance(value, want)
        if not ok:
            raise damaged(f"entry 'meta' has {name} = {value!r}, of the wrong type")
    for name in meta.pop("_nan", []):
        if name not in META_FIELDS or meta.get(name) is not None:
            raise damaged(f"entry 'meta' lists {name!r} as NaN")
        meta[name] = float("nan")
    kwargs = {name: data[name] for name in ARRAY_FIELDS if name in data}
    kwargs["qp_status"] = [str(s) for s in data["qp_status"].reshape(-1)]
    if "qp_binding" in data:  # results saved before it was recorded have none
        kwargs["qp_binding"] = [str(s) for s in data["qp_binding"].reshape(-1)]
    events = [data[name].reshape(-1) for name in ("events_t", "events_kind", "events_message")]
    if len({e.shape[0] for e in events}) != 1:
        raise damaged("entries 'events_t', 'events_kind' and 'events_message' differ in length")
    kwargs["events"] = list(zip(events[0].tolist(), events[1].tolist(), events[2].tolist()))
    try:
        return SimulationResult(**kwargs, **meta)
    except (ValueError, TypeError) as exc:
        raise damaged(f"its arrays do not fit together ({' '.join(str(exc).split())})") from None
