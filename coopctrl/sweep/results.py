"""The :class:`SweepResult`: one summary row per run, ordered by run index, as a table, csv and JSON.

A row is a flat dict: ``run`` (index), one column per swept path (its value), ``status``
(:data:`RUN_STATUSES`), ``reason`` (empty when ok), then :data:`METRICS` taken from the run's
:meth:`~coopctrl.results.SimulationResult.summary` (``None`` when the run has no such figure, e.g.
an ``error`` row). Rows hold no NaN: missing or non-finite figures are ``None``.

Only :data:`TIMING_COLUMNS` depend on the machine and the load; the other columns of a row depend
only on the scenario and its overrides (the sensor noise seed is part of the scenario), so they are
the same with any number of jobs or on a Dask cluster.
"""

from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from coopctrl.compact_repr import compact_repr
from coopctrl.io.console import visible
from coopctrl.sweep.grid import SweepGrid, value_of, value_text

#: Status of a run: the simulation's own (``ok``, ``diverged``, ``qp_failed``), ``error`` when the
#: run raised (the reason names the exception type and its message), or ``timeout`` when it went past
#: the sweep's run timeout.
RUN_STATUSES = ("ok", "diverged", "qp_failed", "error", "timeout")


@dataclass(frozen=True)
class Metric:
    """A summary figure kept in each row.

    Attributes:
        key: Key in the summary and the row (SI units, named in the key's suffix).
        label: Column header of the text table (with the unit shown).
        scale: Factor from the SI value to the table's unit, or ``None`` for an integer count.
        in_table: Whether the text table shows it (the csv and JSON always have every metric).
    """

    key: str
    label: str
    scale: float | None = 1.0
    in_table: bool = True


#: The summary figures of a row, in column order.
METRICS = (
    Metric("simulated_time_s", "t end [s]", in_table=False),
    Metric("object_position_error_rms_m", "pos RMS [mm]", 1e3),
    Metric("object_position_error_max_m", "pos max [mm]", 1e3),
    Metric("object_orientation_error_max_rad", "ori max [mrad]", 1e3, in_table=False),
    Metric("follower_force_error_rms_N", "force RMS [N]"),
    Metric("internal_force_error_rms_N", "squeeze RMS [N]"),
    Metric("max_torque_ratio", "|tau|/tau_max"),
    Metric("qp_failures", "QP fails", None, in_table=False),
    Metric("torque_saturated_ticks", "saturated", None, in_table=False),
    Metric("realtime_factor", "RTF"),
    Metric("wall_time_s", "wall [s]"),
)

#: Columns measured on the wall clock: they vary from run to run, everything else is reproducible.
#: ``realtime_factor`` is simulated time over the loop's wall time; ``wall_time_s`` is the run from its
#: first tick [s]: the worker's start-up (imports, building the scene) is excluded.
TIMING_COLUMNS = ("realtime_factor", "wall_time_s")

#: The file names written into an output directory.
CSV_NAME, JSON_NAME = "sweep.csv", "sweep.json"


def make_row(index: int, columns: Mapping[str, Any], status: str, reason: str,
             summary: Mapping[str, Any] | None, wall_time_s: float | None) -> dict[str, Any]:
    """One row: ``run``, the grid ``columns``, ``status``, ``reason`` and the :data:`METRICS` of ``summary``."""
    from coopctrl.results.summary import json_safe

    if status not in RUN_STATUSES:
        raise ValueError(f"sweep row: status = {status!r} is invalid: expected one of {RUN_STATUSES}")
    summary = summary or {}
    row: dict[str, Any] = {"run": int(index), **dict(columns), "status": status, "reason": " ".join(str(reason or "").split())}
    for metric in METRICS:
        row[metric.key] = summary.get(metric.key)
    row["wall_time_s"] = wall_time_s
    return json_safe(row)


def _cell(value: Any) -> str:
    """A csv cell: empty for ``None``, ``repr`` precision for floats, TOML/JSON text for lists."""
    if value is None:
        return ""
    if isinstance(value, float):
        return repr(value)
    return value_text(value)


def _table_cell(value: Any, scale: float | None) -> str:
    if value is None:
        return "-"
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return value_text(value)
    if scale is None:
        return str(value)
    return f"{value * scale:.4g}"


@dataclass(frozen=True)
class SweepResult:
    """The rows of a sweep, by run index whatever the order in which the runs finished.

    Attributes:
        scenario: The scenario's name.
        source: The scenario file, or ``None`` for the default scene.
        grid: The swept axes.
        sets: The fixed overrides ``(path, value text)``.
        rows: One dict per finished run, sorted by ``run`` (see the module docstring).
        runs: Number of runs planned (``len(rows) < runs`` after an interruption).
        retried: ``(run, cause)`` of each run retried in a fresh worker because a worker process died while
            it ran (``cause``: how that worker died, e.g. ``"killed by signal 9 (SIGKILL)"``;
            :mod:`coopctrl.sweep.lost_worker`). Its row is the retry's.
    """

    scenario: str
    source: str | None
    grid: SweepGrid
    sets: tuple[tuple[str, Any], ...]
    rows: tuple[dict[str, Any], ...]
    runs: int
    retried: tuple[tuple[int, str], ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "rows", tuple(sorted(self.rows, key=lambda row: row["run"])))

    def __repr__(self) -> str:
        """A few lines: scene, grid, runs finished and failed (``table()`` prints the rows)."""
        return compact_repr(self, ["scenario", "source", "runs"],
                            extra=[("grid", self.grid.paths), ("finished", len(self.rows)), ("failed", len(self.failed))])

    @property
    def complete(self) -> bool:
        """True when every planned run has its row."""
        return len(self.rows) == self.runs

    @property
    def failed(self) -> tuple[dict[str, Any], ...]:
        """The rows whose status is not ``ok``."""
        return tuple(row for row in self.rows if row["status"] != "ok")

    @property
    def columns(self) -> tuple[str, ...]:
        """Column names, in order: run, the swept paths, status, reason, the metrics."""
        return ("run", *self.grid.paths, "status", "reason", *(m.key for m in METRICS))

    def reproducible_rows(self) -> list[dict[str, Any]]:
        """The rows without the :data:`TIMING_COLUMNS`: the same for any executor and number of jobs."""
        return [{k: v for k, v in row.items() if k not in TIMING_COLUMNS} for row in self.rows]

    # ------------------------------------------------------------------ formats
    def to_dict(self) -> dict[str, Any]:
        """The JSON document: scenario, grid, fixed overrides, counts and rows (no NaN: ``None``)."""
        from coopctrl.results.summary import json_safe

        return json_safe({
            "scenario": self.scenario,
            "source": self.source,
            "grid": self.grid.to_dict(),
            "set": {path: value_of(text) for path, text in self.sets},
            "runs": self.runs,
            "finished": len(self.rows),
            "failed": len(self.failed),
            "complete": self.complete,
            "retried": [{"run": run, "cause": cause} for run, cause in self.retried],
            "columns": list(self.columns),
            "rows": [dict(row) for row in self.rows],
        })

    def to_json(self) -> str:
        """:meth:`to_dict` as JSON text (strict: ``allow_nan=False``)."""
        return json.dumps(self.to_dict(), indent=2, allow_nan=False)

    def to_csv(self) -> str:
        """One header line (:attr:`columns`) and one line per row; ``None`` is an empty cell."""
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(self.columns)
        for row in self.rows:
            writer.writerow([_cell(row.get(column)) for column in self.columns])
        return buffer.getvalue()

    def table(self) -> str:
        """An aligned text table of the rows (the table's metrics, scaled to their units), then one
        line per failed run with its reason."""
        shown = [m for m in METRICS if m.in_table]
        header = ["run", *self.grid.paths, "status", *(m.label for m in shown)]
        body = [[str(row["run"]), *(_table_cell(row.get(p), None) for p in self.grid.paths), row["status"],
                 *(_table_cell(row.get(m.key), m.scale) for m in shown)] for row in self.rows]
        widths = [max(len(line[c]) for line in [header, *body]) for c in range(len(header))]
        left = 2 + len(self.grid.paths)  # run, the grid values and the status are left-aligned

        def fmt(line: list[str]) -> str:
            cells = [cell.ljust(w) if c < left else cell.rjust(w) for c, (cell, w) in enumerate(zip(line, widths))]
            return "  ".join(cells).rstrip()

        lines = [fmt(header), *(fmt(line) for line in body)]
        lines += [f"run {row['run']} {row['status']}: {row['reason'] or 'no reason given'}" for row in self.failed]
        lines += [f"run {run} retried in a fresh worker: a worker of its pool {cause} while it ran" for run, cause in self.retried]
        return "\n".join(visible(line) for line in lines)

    def save(self, directory: str | Path) -> list[Path]:
        """Write ``sweep.csv`` and ``sweep.json`` into ``directory`` as one unit: both are written into a
        sibling temporary folder that then replaces ``directory`` in one step
        (:mod:`coopctrl.io.atomic_dir`), so a reader always finds the two files of the same save.
        ``directory`` must be new, empty or an earlier sweep's folder
        (:func:`coopctrl.io.output_folder.check_output_folder`). Returns the paths written.

        Raises:
            ValueError: ``directory`` holds files that a sweep does not write.
            OutputWriteError: the system refused a write (a full disk); ``directory`` is as it was.
        """
        from coopctrl.io.atomic_dir import atomic_directory
        from coopctrl.io.console import writing
        from coopctrl.io.output_folder import SWEEP_FOLDER, check_output_folder

        directory = Path(directory)
        check_output_folder(directory, SWEEP_FOLDER)
        texts = ((CSV_NAME, self.to_csv()), (JSON_NAME, self.to_json() + "\n"))
        with writing(str(directory)), atomic_directory(directory) as folder:
            for name, text in texts:
                with writing(str(directory / name)), open(folder / name, "w", encoding="utf-8", newline="") as handle:
                    handle.write(text)
                    handle.flush()
                    os.fsync(handle.fileno())
        return [directory / name for name, _ in texts]
