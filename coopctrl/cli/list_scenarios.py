"""``coopctrl list``: the built-in scenarios with their descriptions."""

from __future__ import annotations

import sys
from pathlib import Path

from coopctrl.cli._core import UsageError, _one_line, scenarios_dir, subcommand
from coopctrl.io.console import say, visible


def cmd_list(args) -> int:
    """Print the scenarios of the directory with their descriptions (each file read as ``load_scenario``
    reads it: regular files of at most 1 MiB, so a FIFO or a device named ``x.toml`` cannot block it)."""
    from coopctrl.scenario.scene_file import scene_description

    directory = Path(args.dir) if args.dir else scenarios_dir()
    if args.dir and not directory.is_dir():
        raise UsageError(f"--dir '{visible(args.dir)}' is invalid: expected an existing directory of scenario .toml files")
    files = sorted(directory.glob("*.toml"))
    if not files:
        print(f"no scenarios in {visible(directory)}", file=sys.stderr)
        return 0
    rows = [(visible(path.stem), _one_line(scene_description(path))) for path in files]  # a name keeps its line breaks, escaped
    width = max(len(name) for name, _ in rows)
    for name, description in rows:
        say(f"{name.ljust(width)}  {description}".rstrip())
    return 0


@subcommand("list")
def _list_parser(sub) -> None:
    parser = sub.add_parser("list", help="list the built-in scenarios", description="List the scenarios (scenarios/*.toml) with their descriptions.")
    parser.add_argument("--dir", metavar="DIR", help="list DIR instead of the built-in scenarios directory")
    parser.set_defaults(handler=cmd_list)
