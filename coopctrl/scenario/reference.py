"""``docs/scenario.md``: the scenario reference, generated from the dataclasses.

Every key the loader accepts (the fields of the sections in :data:`coopctrl.scenario.loader.SECTIONS`)
gets one row: its dotted path, type, unit, default and allowed values (from the field's
:func:`~coopctrl.scenario.schema.key` metadata) and its description (from the ``Attributes:``
section of its class docstring). ``tests/test_scenario_reference.py`` fails when the file and the
dataclasses differ. Regenerate with::

    python -m coopctrl.scenario.reference docs/scenario.md
"""

from __future__ import annotations

import inspect
import re
import sys
from dataclasses import MISSING, fields
from pathlib import Path

from coopctrl.scenario.arm import MAX_DH_JOINTS
from coopctrl.scenario.checks import fmt_bound
from coopctrl.scenario.loader import SECTIONS, _keys
from coopctrl.scenario.scenario import MAX_ARMS, MAX_VIA_POINTS, MIN_CONTACT_DISTANCE_M, Scenario
from coopctrl.scenario.scene_file import MAX_SCENE_BYTES
from coopctrl.scenario.text import MAX_DEPTH, MAX_TEXT
from coopctrl.scenario.schema import range_text, spec

HEADER = """# Scenario reference

Generated from the dataclasses of `coopctrl/scenario/` by
`python -m coopctrl.scenario.reference docs/scenario.md`; do not edit by hand
(`tests/test_scenario_reference.py` fails when this file and the code differ).

A scenario is a TOML file. A scene file must have `[[arms]]` (at least two) and `[trajectory]`;
every other key has the default shown. `coopctrl run` without a file runs the built-in default
scene (two planar 3R arms lifting a 1 kg box by 0.1 m in 1 s). `coopctrl show SCENARIO` prints a
scene with every default filled in. Units are SI. Ranges are inclusive unless written `> 0`; a
value outside its range is refused (exit 2) with one line naming the key, the value and the range.
"Absent" means the key is left out (TOML has no null). Paths are the ones `--set` takes
(`springs[0].stiffness`, `controllers.leader.natural_frequency`).

Limits of the file itself (each refused with exit 2 and one line, before anything runs): a scene
file is a regular file (not a folder, FIFO or device) of at most {max_bytes} bytes ({mib:g} MiB) in UTF-8; tables
and arrays nest at most {max_depth} levels; every key and string (and every `--set` value) is at most
{max_text} characters of text without control characters (C0 but tab, DEL, C1) or lone surrogates.
A scene has 2 to {max_arms} arms, whose contact points (`arms[i].grasp`, first 2 values planar, 3
spatial) are at least {min_contact} m apart, at most {max_via} via points, and a `dh` arm at most
{max_dh} joints.
""".format(max_bytes=MAX_SCENE_BYTES, max_depth=MAX_DEPTH, max_text=MAX_TEXT, max_arms=MAX_ARMS,
           min_contact=fmt_bound(MIN_CONTACT_DISTANCE_M), mib=MAX_SCENE_BYTES / 2**20, max_via=MAX_VIA_POINTS, max_dh=MAX_DH_JOINTS)


def _attributes(cls: type) -> dict[str, str]:
    """Field descriptions from the ``Attributes:`` section of the docstrings along the MRO."""
    out: dict[str, str] = {}
    for klass in reversed(cls.__mro__):
        doc = inspect.getdoc(klass) if klass.__doc__ else None
        if not doc or "Attributes:" not in doc:
            continue
        block = doc.split("Attributes:", 1)[1]
        current: list[str] | None = None
        for line in block.splitlines():
            if line and not line.startswith(" "):
                break  # end of the indented section
            m = re.match(r"^ {4}([A-Za-z_][\w, ]*):\s*(.*)$", line)
            if m:
                names = [n.strip() for n in m.group(1).split(",")]
                current = [m.group(2)]
                for name in names:
                    out[name] = current  # type: ignore[assignment]
            elif current is not None and line.strip():
                current.append(line.strip())
        for name, parts in list(out.items()):
            if isinstance(parts, list):
                out[name] = " ".join(parts)
    return out


def _type_text(annotation: str) -> str:
    text = str(annotation).replace("typing.", "")
    optional = "| None" in text
    text = text.replace(" | None", "")
    text = (text.replace("tuple[float, ...]", "list of floats").replace("tuple[int, int]", "[int, int]")
            .replace("tuple[ViaPoint, ...]", "list of via tables").replace("str", "string")
            .replace("bool", "boolean").replace("int", "integer").replace(" | ", " or "))
    if text.startswith("tuple[") and text.endswith(", ...]"):
        text = "list of " + text[6:-6] + " tables"
    return text + (", optional" if optional else "")


def _toml(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return f'"{value}"'
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    return str(value)


def _default_text(cls: type, f) -> str:
    if f.default is MISSING and f.default_factory is MISSING:
        return "required"
    if f.default_factory is not MISSING:
        sub = SECTIONS.get(cls, {}).get(f.name)
        if isinstance(sub, list):
            return "built-in scene only"
        return "table"
    if f.default is None:
        return "absent"
    return f"`{_toml(f.default)}`"


_UNIT_TOKENS = {"m", "s", "kg", "N", "rad", "J", "W", "Hz", "1", "deg", "mm", "and"}


def _unit_text(meta: dict, description: str) -> str:
    """The declared unit, else the first ``[unit]`` of the description made of SI unit tokens."""
    if meta.get("unit"):
        return meta["unit"]
    for m in re.finditer(r"\[([^\]]+)\]", description):
        tokens = [t for t in re.split(r"[ ,/^*()\-]+", m.group(1)) if t and not t.isdigit()]
        if tokens and all(t in _UNIT_TOKENS for t in tokens):
            return m.group(1)
    return ""


def _escape(text: str) -> str:
    return text.replace("|", "\\|")


def _title(cls: type, path: str, array: bool) -> str:
    if not path:
        return "Top level"
    return f"[[{path}]]" if array else f"[{path}]"


def _walk(cls: type, path: str = "", array: bool = False):
    """Yield (section title, class, path prefix of its keys) in file order, depth first."""
    yield _title(cls, path, array), cls, path
    for name in _keys(cls):
        sub = SECTIONS.get(cls, {}).get(name)
        if sub is None:
            continue
        sub_path = f"{path}.{name}" if path else name
        if isinstance(sub, list):
            yield from _walk(sub[0], sub_path + "[k]", array=True)
        else:
            yield from _walk(sub, sub_path)


def accepted_keys() -> list[str]:
    """Every dotted key path the loader accepts (list entries as ``[k]``), in file order."""
    out = []
    for _title_, cls, path in _walk(Scenario):
        for name in _keys(cls):
            out.append(f"{path}.{name}" if path else name)
    return out


def scenario_reference() -> str:
    """The text of ``docs/scenario.md``."""
    lines = [HEADER]
    ranges: list[str] = []
    for title, cls, path in _walk(Scenario):
        title = title.replace("[k]]]", "]]").replace("[k]", "[]") if title.startswith("[[") else title
        lines.append(f"## {title}\n")
        doc = inspect.getdoc(cls) or ""
        first = doc.split("\n\n", 1)[0].replace("\n", " ")
        lines.append(f"{first} (`{cls.__module__}.{cls.__name__}`)\n")
        lines.append("| key | type | unit | default | allowed | description |")
        lines.append("|---|---|---|---|---|---|")
        described = _attributes(cls)
        keys = _keys(cls)
        for f in fields(cls):
            if f.name not in keys:
                continue
            full = f"{path}.{f.name}" if path else f.name
            meta = spec(cls, f.name)
            sub = SECTIONS.get(cls, {}).get(f.name)
            description = described.get(f.name, "")
            if sub is not None:
                kind = "list of tables" if isinstance(sub, list) else "table"
                unit = ""
                description = description or f"see [{full}]"
            else:
                kind = _type_text(f.type)
                unit = _unit_text(meta, description) if kind.split(",")[0] not in ("boolean", "string") else ""
            row = [f"`{full}`", kind, unit, _default_text(cls, f),
                   range_text(meta), description]
            lines.append("| " + " | ".join(_escape(c) for c in row) + " |")
            if meta.get("why"):
                ranges.append(f"- `{full}` ({range_text(meta)}): {meta['why']}.")
        lines.append("")
    lines.append("## Why these ranges\n")
    lines.append("Each range keeps a value physically meaningful and the numerics finite; the reason, per key:\n")
    lines.extend(ranges)
    lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Write the reference to the path given (default: print it)."""
    argv = sys.argv[1:] if argv is None else argv
    text = scenario_reference()
    if argv:
        Path(argv[0]).write_text(text, encoding="utf-8")
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
