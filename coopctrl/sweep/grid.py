"""The :class:`SweepGrid`: the axes of a sweep and their Cartesian product.

A ``--grid`` argument is ``PATH=V1,V2,...``: ``PATH`` is a dotted scenario path as for ``--set``
(``simulation.integrator``, ``springs[0].stiffness``, ``arms[1].grasp``) and each value is in TOML
syntax, as for ``--set`` (``1e6``, ``true``, ``[0.1, 0, 3.14]``, ``"text"``; a bare word such as
``rk4`` is a string).

Split rule: the value list is split on the commas at bracket depth 0 and outside quoted strings, so
``arms[1].grasp=[0.1,0,3.14],[0.1,0,3.0]`` has two values and ``name="a,b",c`` has two. Brackets
``[]`` and braces ``{}`` count as depth; a backslash escapes a quote inside ``"..."``. Spaces around
a value are ignored. An empty value, unbalanced brackets or quotes, a value given twice and a path
given twice are errors.

Order: the product runs over the axes in the order given, the last axis varying fastest (like
:func:`itertools.product`), and run ``k`` is the ``k``-th combination.

Size: a grid has at most :data:`MAX_RUNS` runs. The count (the product of the axis lengths) is
checked when the grid is built, before any combination is expanded or validated, so that a grid of
1e8 points is refused at once instead of filling the memory.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

from coopctrl.sweep.errors import GridError

#: Most runs of one sweep (the product of the axis lengths). Every run is validated before the first
#: starts and keeps a row in memory; split a larger study into several sweeps.
MAX_RUNS = 10_000

_OPEN, _CLOSE = "[{", "]}"
_FORM = ("PATH=V1,V2,... with values in TOML syntax, e.g. --grid simulation.integrator=rk4,euler "
         "or --grid 'arms[1].grasp=[0.1,0,3.14],[0.1,0,3.0]'")


def split_values(text: str, argument: str | None = None) -> tuple[str, ...]:
    """Split ``"1,[0.1,0,3.14],\\"a,b\\""`` on the commas at bracket depth 0 outside quotes.

    Raises:
        GridError: An empty value or unbalanced brackets or quotes (naming ``argument``).
    """
    argument = text if argument is None else argument
    parts: list[str] = []
    depth, quote, start, i = 0, "", 0, 0
    while i < len(text):
        ch = text[i]
        if quote:
            if ch == "\\" and quote == '"':
                i += 1  # skip the escaped character
            elif ch == quote:
                quote = ""
        elif ch in "\"'":
            quote = ch
        elif ch in _OPEN:
            depth += 1
        elif ch in _CLOSE:
            depth -= 1
            if depth < 0:
                raise GridError(argument, f"balanced brackets: a '{ch}' at character {i + 1} of the values closes nothing")
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
        i += 1
    if quote:
        raise GridError(argument, f"balanced quotes: a {quote} is not closed")
    if depth:
        raise GridError(argument, "balanced brackets: a '[' or '{' is not closed")
    parts.append(text[start:])
    values = tuple(p.strip() for p in parts)
    if any(not v for v in values):
        raise GridError(argument, "a non-empty value between every two commas (no ',,' and no trailing comma); " + _FORM)
    return values


def value_of(text: Any) -> Any:
    """The value a grid entry stands for: a TOML value if the text parses, else the bare string (the
    rule of ``--set``)."""
    from coopctrl.scenario.loader import parse_override_value

    return parse_override_value(text)


def value_text(value: Any) -> str:
    """A grid value as it would be typed: strings bare, the rest in TOML/JSON syntax."""
    import json

    if isinstance(value, str):
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and not math.isfinite(value):
        return str(value)
    try:
        return json.dumps(value, separators=(",", ":"))
    except (TypeError, ValueError):
        return str(value)


@dataclass(frozen=True)
class SweepAxis:
    """One ``--grid`` axis.

    Attributes:
        path: Dotted scenario path (``controllers.followers.force_ki``).
        values: The values to try, each a TOML text (``"40"``, ``"[0.1,0,3.14]"``) or a Python value.
    """

    path: str
    values: tuple[Any, ...]

    def __post_init__(self) -> None:
        from coopctrl.errors import ScenarioError
        from coopctrl.scenario.loader import parse_override_path

        path = self.path.strip() if isinstance(self.path, str) else self.path
        object.__setattr__(self, "path", path)
        object.__setattr__(self, "values", tuple(self.values))
        try:
            parse_override_path(path)
        except ScenarioError:
            raise GridError(f"{path}=...", "a dotted PATH like simulation.integrator or springs[0].stiffness; " + _FORM) from None
        if not self.values:
            raise GridError(f"{path}=", "at least one value; " + _FORM)
        if len(self.values) > MAX_RUNS:
            raise GridError(f"{path}=...", f"at most {MAX_RUNS} values on one axis (it has {len(self.values)}): "
                            f"a sweep has at most {MAX_RUNS} runs")
        seen: set[str] = set()
        for text in self.values:
            value = value_of(text)
            marker = f"{type(value).__name__}:{value_text(value)}"  # equal values of one type, one text
            if marker in seen:
                argument = f"{path}={','.join(map(value_text, self.values))}"
                raise GridError(argument, f"distinct values: {value_text(value)} is given twice")
            seen.add(marker)


@dataclass(frozen=True)
class SweepGrid:
    """The axes of a sweep; its runs are their Cartesian product (last axis fastest).

    Attributes:
        axes: The axes in the order given. No axis means one run with the fixed overrides only.
    """

    axes: tuple[SweepAxis, ...] = ()

    def __post_init__(self) -> None:
        object.__setattr__(self, "axes", tuple(self.axes))
        from coopctrl.scenario.loader import parse_override_path

        seen: dict[tuple, str] = {}
        for axis in self.axes:
            key = tuple(parse_override_path(axis.path))
            if key in seen:
                raise GridError(f"{axis.path}=...", f"each PATH in one --grid only ({axis.path} is already swept)")
            seen[key] = axis.path
        runs = len(self)  # counted, never expanded
        if runs > MAX_RUNS:
            sizes = " x ".join(str(len(axis.values)) for axis in self.axes)
            raise GridError(" ".join(f"{axis.path}=..." for axis in self.axes),
                            f"at most {MAX_RUNS} runs in one sweep; this grid has {sizes} = {runs} runs "
                            "(split it into several sweeps)")

    @classmethod
    def parse(cls, arguments: Iterable[str]) -> "SweepGrid":
        """The grid of the ``--grid PATH=V1,V2,...`` arguments (see the module docstring for the split rule).

        Raises:
            GridError: A malformed argument (the message quotes it).
        """
        axes = []
        for argument in arguments:
            path, sep, values = argument.partition("=")
            if not sep or not path.strip():
                raise GridError(argument, _FORM)
            try:
                axes.append(SweepAxis(path.strip(), split_values(values, argument)))
            except GridError as err:
                raise GridError(argument, err.allowed) from None
        return cls(tuple(axes))

    @classmethod
    def from_mapping(cls, axes: Mapping[str, Iterable[Any]]) -> "SweepGrid":
        """A grid from ``{"simulation.integrator": ["rk4", "euler"], "springs[0].stiffness": [1e4, 2e4]}``."""
        return cls(tuple(SweepAxis(path, tuple(values)) for path, values in axes.items()))

    @property
    def paths(self) -> tuple[str, ...]:
        """The swept paths, in order (the grid columns of the rows)."""
        return tuple(axis.path for axis in self.axes)

    def __len__(self) -> int:
        """Number of runs: the product of the axis lengths (1 without axes)."""
        return math.prod(len(axis.values) for axis in self.axes)

    def combinations(self) -> tuple[dict[str, Any], ...]:
        """The overrides of each run ``{path: value text}``, run 0 first (last axis fastest)."""
        return tuple(dict(zip(self.paths, combo)) for combo in itertools.product(*(axis.values for axis in self.axes)))

    def to_dict(self) -> dict[str, list[Any]]:
        """``{path: [values]}`` with the values parsed (JSON-ready after :func:`~coopctrl.results.json_safe`)."""
        return {axis.path: [value_of(v) for v in axis.values] for axis in self.axes}

    @staticmethod
    def describe(combination: Mapping[str, Any]) -> str:
        """``"a=1, b=rk4"``: one run's overrides on one line."""
        return ", ".join(f"{path}={value_text(value_of(value))}" for path, value in combination.items())
