"""The CLI reference, rendered from :func:`coopctrl.cli.build_parser` when the site is built.

``docs/cli.md`` holds the marker ``<!-- cli-reference -->``; this MkDocs hook replaces it with one
section per subcommand (its usage line, description and a table of every option), so the page
cannot fall behind the parser. ``render()`` is also what ``tests/test_docs_site.py`` checks.
"""

from __future__ import annotations

import argparse

MARKER = "<!-- cli-reference -->"


def _cell(text: str) -> str:
    """Text safe inside a Markdown table cell."""
    return " ".join(str(text).split()).replace("|", "\\|").replace("<", "&lt;").replace(">", "&gt;")


def _option_row(action: argparse.Action) -> str:
    if action.option_strings:
        names = ", ".join(f"`{name}`" for name in action.option_strings)
        if action.nargs != 0:
            names += f" `{action.metavar or action.dest.upper()}`"
    else:
        names = f"`{action.metavar or action.dest}`"
    default = action.default
    shown = "" if default in (None, False, [], (), argparse.SUPPRESS) or action.nargs == 0 else f"`{default}`"
    choices = ", ".join(f"`{c}`" for c in action.choices) if action.choices else ""
    help_text = "" if action.help in (None, argparse.SUPPRESS) else action.help
    if help_text and "%(" in help_text:
        help_text = help_text % {**vars(action), "prog": "coopctrl", "default": default}
    return f"| {names} | {_cell(help_text)} | {_cell(shown)} | {_cell(choices)} |"


def subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """The subcommands' parsers by name, in the order of ``coopctrl --help``."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def render() -> str:
    """The Markdown of every subcommand and option of ``coopctrl``."""
    from coopctrl.cli import build_parser

    parser = build_parser()
    parts = [f"```text\n{parser.format_usage().strip()}\n```\n", _cell(parser.description or ""), "",
             _cell(parser.epilog or ""), ""]
    for name, sub in subparsers(parser).items():
        parts += [f"## `coopctrl {name}`", "", f"```text\n{sub.format_usage().strip()}\n```", "",
                  _cell(sub.description or ""), ""]
        rows = [_option_row(a) for a in sub._actions]
        if rows:
            parts += ["| option | meaning | default | choices |", "|---|---|---|---|", *rows, ""]
        if sub.epilog:
            parts += [_cell(sub.epilog), ""]
    return "\n".join(parts)


def on_page_markdown(markdown: str, page, config, files) -> str:  # noqa: ARG001 - MkDocs hook signature
    """Fill the CLI page's marker with :func:`render`."""
    return markdown.replace(MARKER, render()) if MARKER in markdown else markdown
