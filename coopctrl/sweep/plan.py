"""The :class:`SweepPlan`: every run of a sweep, each validated before any is simulated.

A :class:`SweepRun` carries the scenario's raw TOML table and its overrides (plain dicts and strings),
not a path, so that a worker on another machine (a Dask cluster) needs no access to the file. A planned
run also carries the :class:`~coopctrl.scenario.Scenario` its validation built (about 3 kB pickled), so
that a worker does not build and check it a second time (about 5 ms a run under load).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Mapping

from coopctrl.compact_repr import compact_repr
from coopctrl.errors import ScenarioError
from coopctrl.sweep.errors import GridError
from coopctrl.sweep.grid import MAX_RUNS, SweepGrid, value_of


@dataclass(frozen=True)
class SweepRun:
    """One run of a sweep.

    Attributes:
        index: Run number, 0-based, in the order of :meth:`SweepGrid.combinations`.
        grid_values: ``(path, value text)`` of each swept path, in grid order.
        sets: ``(path, value text)`` of the fixed overrides applied to every run (``--set``).
        source: The scenario file (for messages), or ``None`` for the built-in default scene.
        data: The scenario file's raw TOML table (the overrides are applied to a copy).
        checked: The validated scenario of ``data`` with :attr:`overrides`, when :func:`plan_sweep` built
            it (``None``: :meth:`scenario` builds it).
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    index: int
    grid_values: tuple[tuple[str, Any], ...]
    sets: tuple[tuple[str, Any], ...] = ()
    source: str | None = None
    data: Mapping[str, Any] = field(default_factory=dict, compare=False, repr=False)
    checked: Any = field(default=None, compare=False, repr=False)

    @property
    def overrides(self) -> dict[str, Any]:
        """The overrides of this run: the fixed ones, then the grid's."""
        return {**dict(self.sets), **dict(self.grid_values)}

    @property
    def columns(self) -> dict[str, Any]:
        """The grid values as row columns ``{path: value}`` (TOML texts parsed)."""
        return {path: value_of(text) for path, text in self.grid_values}

    def scenario(self):
        """The validated :class:`~coopctrl.scenario.Scenario` of this run."""
        if self.checked is not None:
            return self.checked
        from coopctrl.scenario.loader import scenario_from_dict

        return scenario_from_dict(self.data, source=self.source, overrides=self.overrides)


@dataclass(frozen=True)
class SweepPlan:
    """The runs of a sweep over one scenario.

    Attributes:
        name: The scenario's name (``planar_two_arm_lift``).
        source: The scenario file, or ``None`` for the default scene.
        grid: The swept axes.
        sets: The fixed overrides ``(path, value text)``.
        runs: One :class:`SweepRun` per combination, by index.
    """

    __repr__ = compact_repr  # a few lines, never whole arrays (coopctrl.compact_repr)

    name: str
    source: str | None
    grid: SweepGrid
    sets: tuple[tuple[str, Any], ...]
    runs: tuple[SweepRun, ...]


def _read_table(path: str | Path) -> dict[str, Any]:
    """The scene file's checked TOML table, read as :func:`~coopctrl.scenario.load_scenario` reads it
    (a regular file of at most 1 MiB)."""
    from coopctrl.scenario.scene_file import read_scene_table

    return read_scene_table(path)


def plan_sweep(scenario_path: str | Path | None, grid: SweepGrid, sets: Mapping[str, Any] | None = None) -> SweepPlan:
    """Validate the scenario with every combination of overrides and return the runs; nothing is simulated.
    A grid has at most :data:`~coopctrl.sweep.grid.MAX_RUNS` runs (counted before any is expanded).

    The fields of each run's scenario are checked (the loader's checks: types, ranges, unknown keys).
    Checks that need the plant (reach of a grasp, torque limits against gravity) happen in the run,
    and a failure there is that run's ``error`` row.

    Args:
        scenario_path: A scenario ``.toml`` file, or ``None`` for the built-in default scene.
        grid: The swept axes.
        sets: Fixed overrides ``{path: value}`` applied to every run before the grid's (``--set``).

    Raises:
        ScenarioError: The file, a ``--set`` or one combination is invalid; the message names the
            field, the value and (for a combination) the run and its overrides.
        GridError: A path is both fixed (``--set``) and swept.
    """
    from coopctrl.scenario.loader import load_scenario, parse_override_path

    sets = dict(sets or {})
    if len(grid) > MAX_RUNS:  # a SweepGrid refuses this when built; the count comes before any expansion
        raise GridError(" ".join(f"{p}=..." for p in grid.paths), f"at most {MAX_RUNS} runs in one sweep (this grid has {len(grid)})")
    base = load_scenario(scenario_path, sets)  # file-level errors and bad --set first
    source = None if scenario_path is None else str(scenario_path)
    data = {} if scenario_path is None else _read_table(scenario_path)
    fixed = {tuple(parse_override_path(p)): p for p in sets}
    for path in grid.paths:
        also = fixed.get(tuple(parse_override_path(path)))
        if also is not None:
            raise GridError(f"{path}=...", f"a path that is not also fixed by --set {also}=...")
    set_items = tuple(sets.items())
    runs = []
    for index, combination in enumerate(grid.combinations()):
        run = SweepRun(index, tuple(combination.items()), set_items, source, data)
        try:
            checked = run.scenario()
        except ScenarioError as err:
            where = f"{source or 'default scene'}, run {index} ({grid.describe(combination)})"
            raise ScenarioError(err.path, err.value, err.allowed, where) from None
        runs.append(replace(run, checked=checked))
    return SweepPlan(base.name, source, grid, set_items, tuple(runs))
