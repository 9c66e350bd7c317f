"""The scenario schema: what each key accepts, declared once, on its dataclass field.

A key is an ordinary dataclass field. Its unit, its range, its allowed values and the reason for
the range are the field's metadata, written with :func:`key`::

    stiffness: float = key(1.0e4, unit="N/m", gt=0, le=1e10, why="a steel contact is about 1e9 N/m")

The section's ``__post_init__`` checks the value against the same declaration
(``number("stiffness", self.stiffness, **limits(self, "stiffness"))``), and the reference
``docs/scenario.md`` (:mod:`coopctrl.scenario.reference`) prints it. A field declared without
:func:`key` is still a key of the file and of the reference: its description and unit then come
from the ``Attributes:`` section of its class docstring.

Pure Python (no numpy): loading a scenario must stay cheap.
"""

from __future__ import annotations

from dataclasses import MISSING, field, fields
from typing import Any, Iterable

from coopctrl.scenario.checks import fmt_bound


def key(
    default: Any = MISSING,
    *,
    default_factory: Any = MISSING,
    unit: str = "",
    gt: float | None = None,
    ge: float | None = None,
    le: float | None = None,
    allowed: Iterable[str] | None = None,
    why: str = "",
):
    """A scenario key: a dataclass field with its schema as metadata.

    Args:
        default, default_factory: As :func:`dataclasses.field` (neither = a required key).
        unit: SI unit of the value (``"N/m"``), ``""`` if dimensionless.
        gt: Exclusive lower bound; only ``0`` is supported (``> 0``).
        ge: Inclusive lower bound.
        le: Inclusive upper bound.
        allowed: The strings the key accepts (a choice).
        why: One sentence justifying the range, printed in docs/scenario.md.
    """
    if gt not in (None, 0):
        raise ValueError("key(gt=...) supports only gt=0; use ge= for other lower bounds")
    meta = {"unit": unit, "gt": gt, "ge": ge, "le": le, "allowed": tuple(allowed) if allowed else None, "why": why}
    if default_factory is not MISSING:
        return field(default_factory=default_factory, metadata={"schema": meta})
    if default is MISSING:
        return field(metadata={"schema": meta})
    return field(default=default, metadata={"schema": meta})


def spec(cls_or_obj: Any, name: str) -> dict:
    """The schema metadata of field ``name`` (empty dict if it was declared without :func:`key`)."""
    cls = cls_or_obj if isinstance(cls_or_obj, type) else type(cls_or_obj)
    table = _SCHEMAS.get(cls)
    if table is None:  # once per class: a scenario's checks ask for about a hundred fields
        table = _SCHEMAS[cls] = {f.name: f.metadata.get("schema", {}) for f in fields(cls)}
    if name not in table:
        raise KeyError(name)
    return dict(table[name])


#: Each configuration class's schema metadata by field name (:func:`spec`).
_SCHEMAS: dict = {}


def limits(cls_or_obj: Any, name: str) -> dict:
    """Keyword arguments of :func:`coopctrl.scenario.checks.number` (``vector``,
    ``scalar_or_vector``) that enforce the declared range and name the unit."""
    meta = spec(cls_or_obj, name)
    out: dict[str, Any] = {}
    if meta.get("gt") == 0:
        out["positive"] = True
    ge = meta.get("ge")
    if ge is not None:
        if ge == 0:
            out["nonnegative"] = True
        else:
            out["minimum"] = ge
    if meta.get("le") is not None:
        out["maximum"] = meta["le"]
    if meta.get("unit"):
        out["unit"] = meta["unit"]
    return out


def range_text(meta: dict) -> str:
    """The declared range as text: ``"> 0 and <= 1e10"``, ``"'a', 'b'"``, or ``""``."""
    if meta.get("allowed"):
        return ", ".join(repr(a) for a in meta["allowed"])
    parts = []
    if meta.get("gt") == 0:
        parts.append("> 0")
    if meta.get("ge") is not None:
        parts.append(f">= {fmt_bound(meta['ge'])}")
    if meta.get("le") is not None:
        parts.append(f"<= {fmt_bound(meta['le'])}")
    return " and ".join(parts)
