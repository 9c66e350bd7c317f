"""A resolved scenario as TOML text, every default filled in and units as comments.

``coopctrl show SCENARIO`` prints :func:`scenario_toml`; loading that text gives back an equal
:class:`~coopctrl.scenario.Scenario` (``tests/test_show.py`` checks it for every shipped scene).
Keys that are absent (TOML has no null) are listed as comments, and ``object.pose`` is left out
because it is the trajectory's first via pose.
"""

from __future__ import annotations

import math
from dataclasses import fields, is_dataclass

from coopctrl.io.console import visible
from coopctrl.io.toml_writer import toml_string
from coopctrl.scenario.loader import SECTIONS, _keys
from coopctrl.scenario.reference import _attributes, _unit_text
from coopctrl.scenario.schema import spec

#: Keys that :func:`scenario_toml` leaves out because another key determines them.
DERIVED = {("ObjectConfig", "pose"): "pose: the trajectory's first via pose (trajectory.via[0].pose)"}


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        if value == 0.0:
            return "0.0"  # never "-0.0" (a pose computed as -1 * 0.0); equal when loaded back
        return repr(value)
    if isinstance(value, str):
        return toml_string(value)
    if is_dataclass(value):
        inner = ", ".join(f"{f.name} = {_value(getattr(value, f.name))}" for f in fields(value)
                          if getattr(value, f.name) is not None)
        return "{" + inner + "}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"cannot write a {type(value).__name__} as TOML")


def _section(lines: list[str], obj, prefix: str) -> None:
    cls = type(obj)
    subs = SECTIONS.get(cls, {})
    described = _attributes(cls)
    later = []
    for name in _keys(cls):
        value = getattr(obj, name)
        derived = DERIVED.get((cls.__name__, name))
        if derived:
            lines.append(f"# {derived}")
            continue
        sub = subs.get(name)
        if sub is not None and not (isinstance(sub, list) and not is_dataclass(sub[0])):
            if isinstance(sub, list) and name == "via":  # a short list: inline tables
                lines.append(f"{name} = [")
                lines.extend(f"  {_value(v)}," for v in value)
                lines.append("]")
            else:
                later.append((name, sub, value))
            continue
        unit = _unit_text(spec(cls, name), described.get(name, ""))
        if value is None:
            lines.append(f"# {name}: absent" + (f" [{unit}]" if unit else ""))
            continue
        if isinstance(value, bool):  # a switch has no unit, whatever the quantity it switches
            unit = ""
        lines.append(f"{name} = {_value(value)}" + (f"  # {unit}" if unit else ""))
    for name, sub, value in later:
        path = prefix + name
        if isinstance(sub, list):
            for item in value:
                lines.extend(["", f"[[{path}]]"])
                _section(lines, item, path + ".")
        else:
            lines.extend(["", f"[{path}]"])
            _section(lines, value, path + ".")


def scenario_toml(scenario) -> str:
    """The scenario as TOML with every default filled in (see the module docstring)."""
    lines = [f"# {visible(scenario.name)}: resolved by `coopctrl show` (every default filled in; units in comments)"]
    _section(lines, scenario, "")
    return "\n".join(lines) + "\n"
