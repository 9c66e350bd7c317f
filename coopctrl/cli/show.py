"""``coopctrl show``: print a scenario with every default filled in, as TOML that loads back."""

from __future__ import annotations

from coopctrl.cli._core import _add_set_option, _load, subcommand
from coopctrl.io.console import say


def cmd_show(args) -> int:
    """Print the resolved scenario (after ``--set``) as TOML; it loads back to an equal scenario."""
    from coopctrl.scenario.to_toml import scenario_toml

    say(scenario_toml(_load(args)).rstrip("\n"))
    return 0


@subcommand("show")
def _show_parser(sub) -> None:
    parser = sub.add_parser(
        "show",
        help="print a scenario with every default filled in (TOML)",
        description="Print the resolved scenario (file, overrides and every default) as TOML that loads "
        "back to the same scenario; units as comments. Keys reference: docs/scenario.md. "
        "Exit 0, or 2 for bad input.",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file or a name in scenarios/ (default: the built-in scene)")
    _add_set_option(parser)
    parser.set_defaults(handler=cmd_show)
