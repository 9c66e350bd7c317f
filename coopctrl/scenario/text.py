"""Safe text in a scene: no control characters, no lone surrogates, bounded nesting.

A scene's strings reach a terminal (``coopctrl check`` prints the name, ``coopctrl list`` the
description), figure titles and file contents. A control character there acts instead of being
shown (ESC starts a terminal escape sequence that can set the window title or clear the screen,
BEL rings), and a lone surrogate (``--set 'name=\\udcff'`` from bytes that are not UTF-8) cannot
be encoded at all and fails late, in matplotlib or in a file write. So every string of a scene,
keys included, is refused at load when it contains one of :data:`CONTROL` (C0 but tab, DEL, C1)
or a code point that UTF-8 cannot encode, naming the field and the character's position.

Nesting: a scene is at most :data:`MAX_DEPTH` levels of tables and arrays deep (the deepest
shipped key, ``arms[0].dh[0][0]``, is 4); deeper input is refused with one line instead of
recursing without bound.

Pure Python (no numpy): loading a scenario must stay cheap.
"""

from __future__ import annotations

import re
from typing import Any, Mapping

from coopctrl.errors import ScenarioError

#: Characters refused in a scene's strings: C0 controls except tab (U+0000-U+0008, U+000A-U+001F),
#: DEL (U+007F) and C1 controls (U+0080-U+009F). Line breaks are control characters too: every
#: string of a scene is one line.
CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f-\x9f]")
#: Lone surrogates (U+D800-U+DFFF): not text, UTF-8 cannot encode them.
SURROGATE = re.compile(r"[\ud800-\udfff]")
#: Deepest nesting of tables and arrays in a scene (the top-level table is level 0).
MAX_DEPTH = 16
#: Longest string of a scene, in characters (a file path is at most 4096 bytes on Linux).
MAX_TEXT = 4096

ALLOWED = "text without control characters (C0 but tab, DEL, C1: escape sequences, bells, line breaks) " \
          "and without lone surrogates (text that is not valid UTF-8)"


def printable(text: str) -> str:
    """``text`` with every control character and lone surrogate escaped (``\\x1b``, ``\\udcff``): safe
    to print in a message."""
    def esc(match: re.Match) -> str:
        return match.group(0).encode("unicode_escape").decode("ascii")

    return SURROGATE.sub(esc, CONTROL.sub(esc, text))


def bad_character(text: str) -> str | None:
    """A description of the first refused character of ``text`` (``"U+001B at character 5"``), or None."""
    for pattern in (CONTROL, SURROGATE):
        found = pattern.search(text)
        if found is not None:
            return f"U+{ord(found.group(0)):04X} at character {found.start() + 1}"
    return None


def check_text(path: str, value: str) -> str:
    """``value`` if it is safe text (see the module docstring), else a :class:`ScenarioError` naming ``path``."""
    if len(value) > MAX_TEXT:
        raise ScenarioError(path, value[:32] + "...", f"text of at most {MAX_TEXT} characters (it has {len(value)})")
    bad = bad_character(value)
    if bad is not None:
        raise ScenarioError(path, value, f"{ALLOWED}; found {bad}")
    return value


def _key_path(prefix: str, key: str) -> str:
    return f"{prefix}.{key}" if prefix else key


#: Leaf types a TOML tree holds that carry no text and no nesting.
_LEAVES = frozenset({float, int, bool})


def check_tree(data: Mapping[str, Any], prefix: str = "") -> None:
    """Check every key and string of a TOML-shaped tree (iteratively, so that any depth is safe):
    safe text (:func:`check_text`) and at most :data:`MAX_DEPTH` levels of tables and arrays.

    Raises:
        ScenarioError: naming the first offending key or value by its dotted path.
    """
    stack: list[tuple[str, Any, int]] = [(prefix, data, 0)]
    while stack:
        path, node, depth = stack.pop()
        kind = type(node)
        if kind in _LEAVES:  # most of a scene: numbers (an exact type test; the ABC test costs more)
            continue
        if kind is str or isinstance(node, str):
            check_text(path or "<scenario>", node)
            continue
        if not (kind is dict or kind is list or isinstance(node, (Mapping, list, tuple))):
            continue
        if depth >= MAX_DEPTH:
            raise ScenarioError(path, "...", f"at most {MAX_DEPTH} levels of nested tables and arrays "
                                "(a scene needs 4)")
        if kind is dict or isinstance(node, Mapping):
            for key, value in reversed(list(node.items())):  # reversed: the first offence is met first
                if isinstance(key, str) and (len(key) > MAX_TEXT or bad_character(key) is not None):
                    where = _key_path(path, printable(key[:32]))
                    raise ScenarioError(where, key[:32], f"a key of {ALLOWED}, at most {MAX_TEXT} characters")
                stack.append((_key_path(path, str(key)), value, depth + 1))
        else:
            for index in range(len(node) - 1, -1, -1):
                stack.append((f"{path}[{index}]", node[index], depth + 1))
