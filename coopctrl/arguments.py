"""Checks of a public function's arguments, made once per call at the API's boundary (never per tick).

Each check returns the argument in the form the function uses, or raises ``TypeError`` (wrong kind of
value) or ``ValueError`` (right kind, wrong value) with one line naming the argument, its value and
what is allowed::

    x0 = array of shape (19,) is invalid: expected a state vector of shape (18,) (the plant's state_size)

The wording is that of :class:`~coopctrl.errors.ScenarioError` (``path = value is invalid: expected
...``), so an API user and a CLI user read the same sentence.
"""

from __future__ import annotations

import math
import numbers
import os
from typing import Any, Mapping

import numpy as np

#: Longest text of a value quoted in a message [characters]; longer ones are cut with an ellipsis.
VALUE_TEXT_MAX = 80


def value_text(value: Any) -> str:
    """A short text of ``value`` for a message: an array by its shape and dtype, others by a cut ``repr``."""
    if isinstance(value, np.ndarray):
        if value.size <= 6:
            return f"array({np.array2string(value, separator=', ', threshold=6)})"
        return f"array of shape {value.shape} and dtype {value.dtype}"
    text = " ".join(repr(value).split())  # one line, whatever the value's own repr
    return text if len(text) <= VALUE_TEXT_MAX else text[:VALUE_TEXT_MAX - 3] + "..."


def invalid(name: str, value: Any, allowed: str, kind: type[Exception] = ValueError) -> Exception:
    """The error ``"<name> = <value> is invalid: expected <allowed>"`` of class ``kind``."""
    return kind(f"{name} = {value_text(value)} is invalid: expected {allowed}")


def flag(name: str, value: Any) -> bool:
    """A ``bool`` (``True``/``False``, numpy's included); anything else is a ``TypeError``."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise invalid(name, value, "True or False", TypeError)


def number(name: str, value: Any, *, minimum: float | None = None, positive: bool = False,
           finite: bool = True, unit: str = "") -> float:
    """A real number (not a bool, not a string) as ``float``: finite unless ``finite=False``, ``> 0`` with
    ``positive``, ``>= minimum`` with ``minimum``. ``unit`` names the SI unit in the message."""
    bound = " > 0" if positive else (f" >= {minimum:g}" if minimum is not None else "")
    what = f"a {'finite ' if finite else ''}number{bound}{f' [{unit}]' if unit else ''}"
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise invalid(name, value, what, TypeError)
    v = float(value)
    if (finite and not math.isfinite(v)) or math.isnan(v):
        raise invalid(name, value, what)
    if (positive and not v > 0.0) or (minimum is not None and not v >= minimum):
        raise invalid(name, value, what)
    return v


def vector(name: str, value: Any, size: int, what: str) -> np.ndarray:
    """A finite float vector of shape ``(size,)`` (a copy); ``what`` says what it is (in the message)."""
    allowed = f"{what}: a sequence or array of {size} finite numbers"
    if value is None or isinstance(value, (str, bytes, Mapping)):
        raise invalid(name, value, allowed, TypeError)
    try:
        arr = np.array(value, dtype=float)
    except (TypeError, ValueError):
        raise invalid(name, value, allowed, TypeError) from None
    if arr.shape != (size,):
        raise invalid(name, value, f"{allowed} (shape ({size},), got {arr.shape})")
    bad = ~np.isfinite(arr)
    if bad.any():
        raise invalid(name, value, f"{allowed} (entry {int(np.argmax(bad))} is {float(arr[bad][0])!r})")
    return arr


def path_or_none(name: str, value: Any, allowed: str) -> None:
    """``None``, a ``str`` or an ``os.PathLike`` (``pathlib.Path``); anything else is a ``TypeError``
    saying ``allowed``."""
    if value is None or isinstance(value, (str, os.PathLike)):
        return
    raise invalid(name, value, allowed, TypeError)


def instance(name: str, value: Any, cls: type, allowed: str) -> Any:
    """``value`` if it is a ``cls``; else a ``TypeError`` saying ``allowed`` (how to get one)."""
    if isinstance(value, cls):
        return value
    raise invalid(name, value, allowed, TypeError)


def callable_or_none(name: str, value: Any, allowed: str) -> Any:
    """``None`` or a callable."""
    if value is None or callable(value):
        return value
    raise invalid(name, value, allowed, TypeError)


def overrides_or_none(name: str, value: Any) -> None:
    """``None`` or a mapping of dotted paths (``str``) to values, as ``load_scenario``'s ``overrides``."""
    allowed = "a mapping of dotted paths to values, e.g. {'simulation.duration': 0.5}, or None"
    if value is None:
        return
    if not isinstance(value, Mapping):
        raise invalid(name, value, allowed, TypeError)
    for key in value:
        if not isinstance(key, str):
            raise invalid(name, value, f"{allowed} (the key {key!r} is not a str)", TypeError)
