"""The options of a benchmark that times chosen shipped scenes: ``--repeats``, ``--scenes`` and ``--quick``.

:func:`add_scene_options` adds them; :func:`chosen_scenarios` checks them and loads every chosen scene before
any work, so that a bad value is one usage line (exit 2), not a traceback after minutes of timing.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import coopctrl
from coopctrl.errors import ScenarioError

REPO = Path(__file__).resolve().parent.parent
#: The shipped scenes, by name.
SCENES = sorted(p.stem for p in (REPO / "scenarios").glob("*.toml"))


def add_scene_options(parser: argparse.ArgumentParser, repeats: int, repeats_help: str, scenes_help: str) -> None:
    """``--repeats`` (default ``repeats``), ``--scenes`` (comma-separated names) and ``--quick`` (the carry,
    3 repeats)."""
    parser.add_argument("--repeats", type=int, default=repeats, help=f"{repeats_help} (default {repeats})")
    parser.add_argument("--scenes", default="", help=scenes_help)
    parser.add_argument("--quick", action="store_true", help="a smoke run: spatial_two_puma_carry, 3 repeats")


def chosen_scenarios(parser: argparse.ArgumentParser, args, default) -> dict:
    """The scenarios of ``--scenes`` (``default`` names when none), each loaded, by name; ``--quick`` applied
    to ``args``. A bad ``--repeats`` or scene ends the benchmark with one usage line (``parser.error``)."""
    if args.quick:
        args.repeats, args.scenes = 3, "spatial_two_puma_carry"
    if args.repeats < 1:
        parser.error(f"--repeats {args.repeats} is invalid: expected an integer >= 1")
    scenarios = {}
    for name in [s for s in args.scenes.split(",") if s] or list(default):
        try:
            scenarios[name] = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml", {})
        except ScenarioError as exc:
            parser.error(f"--scenes {name}: {exc}")
    return scenarios
