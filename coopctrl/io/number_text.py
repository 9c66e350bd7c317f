"""Numbers as text for people: never ``-0``.

``format(-0.0, ".4g")`` is ``"-0"`` and ``format(-1e-17, ".3f")`` is ``"-0.000"``: a pose computed as
``-1 * 0.0``, or rounded from a tiny negative value, would print a sign that means nothing. Every pose
or vector the project prints in a sentence goes through :func:`number_text`.
"""

from __future__ import annotations


def number_text(value: float, spec: str = ".4g") -> str:
    """``value`` formatted with the format ``spec`` (``".4g"``, ``"+.2f"``, ...), with the sign dropped
    when the text reads as zero (``-0``, ``-0.000``, ``+0.00`` keeps its ``+`` for a ``+`` spec)."""
    text = format(float(value), spec)
    if text.startswith("-"):
        try:
            zero = float(text) == 0.0
        except ValueError:  # a spec with text around the number: leave it as it is
            return text
        if zero:
            return ("+" if "+" in spec else "") + text[1:]
    return text


def numbers_text(values, spec: str = ".4g", sep: str = ", ") -> str:
    """The entries of ``values`` by :func:`number_text`, joined by ``sep``."""
    return sep.join(number_text(v, spec) for v in values)
