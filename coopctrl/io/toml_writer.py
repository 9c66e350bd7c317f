"""A small TOML writer for TOML-shaped dicts (the standard library only reads TOML).

Enough for :meth:`coopctrl.scenario.Scenario.to_dict` output: tables, arrays of tables, strings,
booleans, integers, floats (``nan``, ``inf``) and arrays of those or of inline tables.
"""

from __future__ import annotations

import json
import math
import re
from typing import Any, Mapping

_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def toml_string(text: str) -> str:
    """``text`` as a TOML basic string that loads back to it, with every character that is not printable
    (controls, bidirectional overrides, invisible marks) written as a ``\\uXXXX`` or ``\\UXXXXXXXX`` escape:
    printed on a terminal (``coopctrl show``), the file shows them instead of acting on them."""
    quoted = json.dumps(text, ensure_ascii=False)  # quotes, backslashes and C0 controls escaped
    if quoted.isprintable():
        return quoted
    return "".join(c if c.isprintable() else (f"\\u{ord(c):04x}" if ord(c) < 0x10000 else f"\\U{ord(c):08x}")
                   for c in quoted)


def _key(key: str) -> str:
    return key if _BARE.match(key) else json.dumps(key)


def _value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return toml_string(value)
    if isinstance(value, Mapping):
        return "{" + ", ".join(f"{_key(str(k))} = {_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"dumps_toml: a value of type {type(value).__name__} cannot be written as TOML")


def _is_table_array(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and bool(value) and all(isinstance(v, Mapping) for v in value)


def _table(lines: list[str], data: Mapping, prefix: str) -> None:
    for k, v in data.items():
        if not isinstance(v, Mapping) and not _is_table_array(v):
            lines.append(f"{_key(str(k))} = {_value(v)}")
    for k, v in data.items():
        name = prefix + _key(str(k))
        if isinstance(v, Mapping):
            lines.extend(["", f"[{name}]"])
            _table(lines, v, name + ".")
        elif _is_table_array(v):
            for item in v:
                lines.extend(["", f"[[{name}]]"])
                _table(lines, item, name + ".")


def dumps_toml(data: Mapping) -> str:
    """Serialise a TOML-shaped dict; ``tomllib.loads(dumps_toml(d)) == d`` for such dicts."""
    lines: list[str] = []
    _table(lines, data, "")
    return "\n".join(lines).lstrip("\n") + "\n"
