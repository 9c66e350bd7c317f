"""The docstrings' Sphinx roles, read as plain code in the API reference.

The code's docstrings cross-reference with Sphinx roles (``:func:`load_scenario```,
``:class:`~coopctrl.results.SimulationResult```), which Markdown renders as ``:func:`` followed by the
code. This MkDocs hook drops the role and, for a ``~`` target, keeps its last name, as Sphinx shows it.
"""

from __future__ import annotations

import re

ROLE = re.compile(r":(?:func|class|mod|meth|attr|data|exc|obj|const):<code>(~?)([^<]*)</code>")


def plain(html: str) -> str:
    """``html`` with each role dropped before its code (``~a.b.C`` shown as ``C``)."""
    return ROLE.sub(lambda m: f"<code>{m.group(2).rsplit('.', 1)[-1] if m.group(1) else m.group(2)}</code>", html)


def on_page_content(html: str, page, config, files) -> str:  # noqa: ARG001 - MkDocs hook signature
    """Render the roles of a page's docstrings as code."""
    return plain(html)
