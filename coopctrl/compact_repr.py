"""Short ``repr`` of result and configuration objects, for a notebook (issue 21 item 6).

A dataclass's generated ``repr`` prints every array in full (a 1001-sample run, a 21 x 21 matrix) and
every list (1001 ``'solved'`` strings). :func:`compact_repr` prints instead, on at most
:data:`MAX_LINES` lines of at most :data:`LINE_WIDTH` characters::

    ForceLoopDesign(kp=0.05, ki=12.3, A=<array 21x21>, margins=Margins(...), ...)

arrays by their shape (small ones in full), long sequences by their length and kind, long strings cut,
nested objects by their own short ``repr`` when it is short, else by their class name. A class
defines ``__repr__`` as ``compact_repr(self, names)`` with the fields worth reading (its key figures);
the fields themselves are unchanged.
"""

from __future__ import annotations

import dataclasses
import numbers
from typing import Any, Iterable

import numpy as np

#: Most lines a compact repr takes; fields beyond are counted ("... 7 more").
MAX_LINES = 4
#: Width of a line [characters].
LINE_WIDTH = 100
#: Longest text of one field's value [characters].
VALUE_WIDTH = 60
#: Arrays and sequences up to this many entries are printed in full (when short enough).
SMALL = 6


def value_text(value: Any) -> str:
    """The short text of one value (see the module docstring)."""
    if isinstance(value, (bool, np.bool_)) or value is None:
        return repr(bool(value) if value is not None else None)
    if isinstance(value, numbers.Integral):
        return str(int(value))
    if isinstance(value, numbers.Real):
        return f"{float(value):.4g}"
    if isinstance(value, str):
        return repr(value) if len(value) <= VALUE_WIDTH else repr(value[:VALUE_WIDTH - 5]) + "..."
    if isinstance(value, np.ndarray):
        if value.size <= SMALL and value.dtype.kind in "biufc":
            text = np.array2string(value, precision=4, separator=", ", threshold=SMALL)
            if len(text) <= VALUE_WIDTH:
                return text
        return f"<array {'x'.join(str(d) for d in value.shape) or 'scalar'} {value.dtype}>"
    if isinstance(value, (list, tuple)) and not hasattr(value, "_fields"):
        if len(value) <= SMALL:
            text = "[" + ", ".join(value_text(v) for v in value) + "]"
            if isinstance(value, tuple):
                text = "(" + text[1:-1] + ("," if len(value) == 1 else "") + ")"
            if len(text) <= VALUE_WIDTH:
                return text
        kinds = sorted({type(v).__name__ for v in value})
        return f"<{type(value).__name__} of {len(value)} {'/'.join(kinds[:3])}>"
    if isinstance(value, dict):
        if len(value) <= SMALL:
            text = "{" + ", ".join(f"{k!r}: {value_text(v)}" for k, v in value.items()) + "}"
            if len(text) <= VALUE_WIDTH:
                return text
        return f"<dict of {len(value)} keys>"
    text = repr(value)
    if len(text) <= VALUE_WIDTH and "\n" not in text:
        return text
    return f"<{type(value).__name__}>"


def _names(obj: Any) -> list[str]:
    if dataclasses.is_dataclass(obj):
        return [f.name for f in dataclasses.fields(obj) if f.repr]
    return [k for k in vars(obj) if not k.startswith("_")]


def compact_repr(obj: Any, names: Iterable[str] | None = None, *, head: str | None = None,
                 extra: Iterable[tuple[str, Any]] = ()) -> str:
    """``ClassName(name=value, ...)`` of ``obj``'s ``names`` (default: every field), then ``extra``
    ``(label, value)`` pairs, in at most :data:`MAX_LINES` lines. ``head`` replaces the class name."""
    items = []
    for name in (_names(obj) if names is None else names):
        try:
            items.append(f"{name}={value_text(getattr(obj, name))}")
        except Exception:  # noqa: BLE001 - a repr must never raise (a property that cannot be computed)
            items.append(f"{name}=?")
    items += [f"{label}={value_text(value)}" for label, value in extra]
    lines, line = [], f"{head or type(obj).__name__}("
    for k, item in enumerate(items):
        piece = item + (", " if k < len(items) - 1 else "")
        if len(line) + len(piece) > LINE_WIDTH and line.strip():
            if len(lines) == MAX_LINES - 1:
                line = line.rstrip() + f" ... {len(items) - k} more"
                items = items[:k]
                break
            lines.append(line.rstrip())
            line = "    "
        line += piece
    return "\n".join(lines + [line.rstrip(", ") + ")"])
