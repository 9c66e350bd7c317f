"""Numbers as text never read ``-0`` (issue 21 item 6)."""

from __future__ import annotations

import pytest

from coopctrl.io.number_text import number_text, numbers_text


@pytest.mark.parametrize("value, spec, text", [
    (-0.0, ".4g", "0"),
    (-1e-17, ".3f", "0.000"),      # rounds to zero: no sign
    (-0.0, "+.2f", "+0.00"),       # a signed spec keeps its sign, and it is +
    (-1e-17, ".4g", "-1e-17"),     # not zero as written: the sign stays
    (-0.25, ".4g", "-0.25"),
    (3.0, ".4g", "3"),
])
def test_number_text(value, spec, text):
    assert number_text(value, spec) == text


def test_numbers_text_joins_a_pose():
    assert numbers_text([0.5, -0.0, -0.0 * 3.0]) == "0.5, 0, 0"
    assert "-0" not in numbers_text([-1e-20, 0.0, -0.0], ".3f")
