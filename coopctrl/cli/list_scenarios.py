"""``coopctrl list``: the built-in scenarios with their descriptions."""

from __future__ import annotations

import sys
from pathlib import Path

from coopctrl.cli._core import _one_line, scenarios_dir, subcommand

def cmd_list(args) -> int:
    """Print the scenarios of the directory with their descriptions."""
    import tomllib

    directory = Path(args.dir) if args.dir else scenarios_dir()
    files = sorted(directory.glob("*.toml"))
    if not files:
        print(f"no scenarios in {directory}", file=sys.stderr)
        return 0
    rows = []
    for path in files:
        try:
            description = tomllib.loads(path.read_text(encoding="utf-8")).get("description", "")
            description = _one_line(description) if isinstance(description, str) else ""
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
            description = f"(unreadable: {_one_line(err)})"
        rows.append((path.stem, description))
    width = max(len(name) for name, _ in rows)
    for name, description in rows:
        print(f"{name.ljust(width)}  {description}".rstrip())
    return 0


@subcommand
def _list_parser(sub) -> None:
    parser = sub.add_parser("list", help="list the built-in scenarios", description="List the scenarios (scenarios/*.toml) with their descriptions.")
    parser.add_argument("--dir", metavar="DIR", help="list DIR instead of the built-in scenarios directory")
    parser.set_defaults(handler=cmd_list)
