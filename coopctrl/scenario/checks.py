"""Field checks shared by the scenario dataclasses.

Every check takes the field's path (relative to the dataclass being built, e.g. ``"grasp"``),
the value received, and returns the value normalised (lists become tuples, ints become floats)
or raises :class:`~coopctrl.errors.ScenarioError` naming the path, the value and what is allowed.
:func:`field_scope` prefixes the path of an error raised inside a nested section, so that a
message always names the full dotted path (``arms[1].grasp``).

Pure Python on purpose: loading and checking a scenario must not import numpy (CLI start-up).
"""

from __future__ import annotations

import math
from contextlib import contextmanager
from typing import Iterable, Iterator

from coopctrl.errors import ScenarioError
from coopctrl.scenario.text import check_text


class _Missing:
    """Sentinel shown as ``<missing>`` for a required key that is absent."""

    def __repr__(self) -> str:
        return "<missing>"


MISSING = _Missing()


def join_path(prefix: str, path: str) -> str:
    """Join a dotted prefix and a relative path (``join_path("arms[1]", "grasp")``)."""
    if not prefix:
        return path
    if not path:
        return prefix
    if path.startswith("["):
        return prefix + path
    return f"{prefix}.{path}"


@contextmanager
def field_scope(prefix: str) -> Iterator[None]:
    """Re-raise a :class:`ScenarioError` from inside a section with ``prefix`` prepended."""
    try:
        yield
    except ScenarioError as err:
        if not prefix:
            raise
        raise ScenarioError(join_path(prefix, err.path), err.value, err.allowed, err.source) from None


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def fmt_bound(value: float) -> str:
    """A bound as short text: ``1e10``, ``1e-06`` -> ``1e-6``, ``0.05``; an integer bound exactly."""
    if isinstance(value, int) and not isinstance(value, bool):
        return str(value)
    text = f"{value:g}"
    if "e" in text:
        mant, exp = text.split("e")
        text = f"{mant}e{int(exp)}"
    return text


def _range_text(positive: bool, nonnegative: bool, minimum, maximum) -> str:
    parts = []
    if positive:
        parts.append("> 0")
    elif nonnegative:
        parts.append(">= 0")
    if minimum is not None:
        parts.append(f">= {fmt_bound(minimum)}")
    if maximum is not None:
        parts.append(f"<= {fmt_bound(maximum)}")
    return " and ".join(parts)


def number(
    path: str,
    value,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    minimum: float | None = None,
    maximum: float | None = None,
    unit: str = "",
) -> float:
    """A finite float; optionally > 0 or >= 0, and within ``[minimum, maximum]`` (the range the
    schema states, :mod:`coopctrl.scenario.schema`). ``unit`` is only used in the message."""
    what = "a finite number"
    bounds = _range_text(positive, nonnegative, minimum, maximum)
    if bounds:
        what += " " + bounds
    if unit:
        what += f" [{unit}]"
    if not _is_number(value):
        raise ScenarioError(path, value, what)
    value = float(value)
    if (
        not math.isfinite(value)
        or (positive and value <= 0.0)
        or (nonnegative and value < 0.0)
        or (minimum is not None and value < minimum)
        or (maximum is not None and value > maximum)
    ):
        raise ScenarioError(path, value, what)
    return value


def optional_number(path: str, value, **kwargs) -> float | None:
    """``None`` (key absent) or :func:`number`."""
    return None if value is None else number(path, value, **kwargs)


def integer(path: str, value, *, minimum: int | None = None, maximum: int | None = None) -> int:
    """An integer (not a bool), optionally >= ``minimum`` and <= ``maximum``."""
    what = "an integer"
    if minimum is not None:
        what += f" >= {minimum}"
    if maximum is not None:
        what += (" and" if minimum is not None else "") + f" <= {maximum}"
    if isinstance(value, bool) or not isinstance(value, int):
        raise ScenarioError(path, value, what)
    if (minimum is not None and value < minimum) or (maximum is not None and value > maximum):
        raise ScenarioError(path, value, what)
    return int(value)


def boolean(path: str, value) -> bool:
    """``true`` or ``false``."""
    if not isinstance(value, bool):
        raise ScenarioError(path, value, "true or false")
    return value


def string(path: str, value, *, nonempty: bool = False, one_line: bool = False) -> str:
    """A string (optionally non-empty, optionally without line breaks) of safe text: no control
    character, no lone surrogate, at most :data:`~coopctrl.scenario.text.MAX_TEXT` characters
    (:func:`coopctrl.scenario.text.check_text`)."""
    what = "a non-empty string" if nonempty else "a string"
    if one_line:
        what += " on one line"
    if not isinstance(value, str) or (nonempty and not value.strip()) or (one_line and ("\n" in value or "\r" in value)):
        raise ScenarioError(path, value, what)
    return check_text(path, value)


def choice(path: str, value, allowed: Iterable[str]) -> str:
    """One of the strings ``allowed``."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise ScenarioError(path, value, "one of " + ", ".join(repr(a) for a in allowed))
    return value


def vector(
    path: str,
    value,
    *,
    lengths: Iterable[int] | None = None,
    positive: bool = False,
    nonnegative: bool = False,
    minimum: float | None = None,
    maximum: float | None = None,
    what: str = "",
    unit: str = "",
) -> tuple[float, ...]:
    """A list of finite numbers, of one of the ``lengths`` if given, each within the bounds."""
    lengths = tuple(lengths) if lengths is not None else None
    desc = "a list of finite numbers"
    bounds = _range_text(positive, nonnegative, minimum, maximum)
    if bounds:
        desc += " " + bounds
    if lengths:
        desc += " of length " + " or ".join(str(n) for n in lengths)
    what = what or unit
    if what:
        desc += f" ({what})"
    if not isinstance(value, (list, tuple)):
        raise ScenarioError(path, value, desc)
    if lengths and len(value) not in lengths:
        raise ScenarioError(path, value, desc)
    out = []
    for item in value:
        if not _is_number(item):
            raise ScenarioError(path, value, desc)
        item = float(item)
        if (
            not math.isfinite(item)
            or (positive and item <= 0.0)
            or (nonnegative and item < 0.0)
            or (minimum is not None and item < minimum)
            or (maximum is not None and item > maximum)
        ):
            raise ScenarioError(path, value, desc)
        out.append(item)
    return tuple(out)


def optional_vector(path: str, value, **kwargs) -> tuple[float, ...] | None:
    """``None`` (key absent) or :func:`vector`."""
    return None if value is None else vector(path, value, **kwargs)


def scalar_or_vector(
    path: str,
    value,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    minimum: float | None = None,
    maximum: float | None = None,
    unit: str = "",
) -> float | tuple[float, ...]:
    """A finite number or a non-empty list of them (per-axis values); length checked by the caller."""
    kw = dict(positive=positive, nonnegative=nonnegative, minimum=minimum, maximum=maximum)
    if isinstance(value, (list, tuple)):
        if not value:
            raise ScenarioError(path, value, "a number or a non-empty list of numbers" + (f" [{unit}]" if unit else ""))
        return vector(path, value, what=unit, **kw)
    return number(path, value, unit=unit, **kw)


def instance(path: str, value, cls: type):
    """An instance of the scenario section ``cls``."""
    if not isinstance(value, cls):
        raise ScenarioError(path, value, f"a {cls.__name__}")
    return value
