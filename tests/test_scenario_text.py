"""Safe text in a scene (coopctrl/scenario/text.py) and the issue-22 examples met through `coopctrl check`:
terminal escapes in the name, a lone surrogate in the name, deep nesting; the escaping of every one-line
error the command line prints."""

from __future__ import annotations

import pytest

from coopctrl import cli
from coopctrl.cli import one_line
from coopctrl.errors import ScenarioError
from coopctrl.io import dumps_toml
from coopctrl.scenario import Scenario, scenario_from_dict
from coopctrl.scenario.text import MAX_DEPTH, bad_character, check_text, check_tree, printable


def one_error_line(capsys, args, code=2) -> str:
    assert cli.main([str(a) for a in args]) == code
    out, err = capsys.readouterr()
    lines = err.splitlines()
    assert out == "" and len(lines) == 1 and lines[0].startswith("coopctrl: error: "), err
    return lines[0]


@pytest.mark.parametrize("text, found", [("a\x1b]0;t\x07", "U+001B at character 2"), ("\x07", "U+0007 at character 1"),
                                         ("x\x7f", "U+007F at character 2"), ("\x85", "U+0085 at character 1"),
                                         ("a\nb", "U+000A at character 2"), ("ab\udcff", "U+DCFF at character 3")])
def test_bad_character_names_the_first(text, found):
    assert bad_character(text) == found
    with pytest.raises(ScenarioError, match=found.replace("+", r"\+")):
        check_text("name", text)


@pytest.mark.parametrize("text", ["", "tab\there", "caf\u00e9 \u4e2d\u6587", "\u2028 is a separator, not C0/C1", "x" * 4096])
def test_good_text_passes(text):
    assert bad_character(text) is None and check_text("name", text) == text


def test_printable_escapes_everything_a_terminal_acts_on():
    shown = printable("a\x1b[2J\x07\x9b\udcff\tb")
    assert shown == "a\\x1b[2J\\x07\\x9b\\udcff\tb"
    assert bad_character(shown.replace("\t", " ")) is None


def test_cli_error_lines_are_escaped():
    assert one_line("bad \x1b]0;x\x07 value\nsecond line") == "bad \\x1b]0;x\\x07 value second line"


def test_terminal_escape_in_the_name_is_refused(tmp_path, capsys):
    """Issue 22: ESC and BEL from the scene's name reached the terminal raw."""
    data = Scenario().to_dict()
    data["name"] = "\x1b]0;owned\x07\x1b[2J"
    path = tmp_path / "escape.toml"
    path.write_text(dumps_toml(data))
    line = one_error_line(capsys, ["check", path])
    assert "name = '\\x1b]0;owned\\x07\\x1b[2J' is invalid" in line and "U+001B at character 1" in line
    assert "\x1b" not in line and "\x07" not in line


def test_lone_surrogate_in_the_name_is_refused_at_load(capsys):
    """Issue 22: a name with a lone surrogate passed validation, ran, then failed in matplotlib."""
    line = one_error_line(capsys, ["run", "--set", "name=x\udcffy", "-q"])
    assert "--set 'name=x\\udcffy' is invalid" in line and "U+DCFF at character 7" in line
    with pytest.raises(ScenarioError, match="name"):
        Scenario(name="x\ud800")


def test_every_string_field_of_the_api_is_checked():
    with pytest.raises(ScenarioError, match="description"):
        Scenario(description="one\x1b")
    with pytest.raises(ScenarioError, match=r"arms\[0\]\.base_link"):
        scenario_from_dict({"arms": [{"model": "urdf", "role": "leader", "base": [0] * 6, "grasp": [0] * 6,
                                      "urdf": "a.urdf", "base_link": "b\x00", "tip_link": "t"}]})


def test_nesting_beyond_the_bound_is_refused_with_its_path():
    deep = 1
    for _ in range(MAX_DEPTH + 1):
        deep = [deep]
    with pytest.raises(ScenarioError, match=r"extra\.x\[0\].*at most 16 levels"):
        check_tree({"extra": {"x": deep}})
    # a recursion-proof walk: far deeper than Python's recursion limit, still one ScenarioError
    deep = 1
    for _ in range(100_000):
        deep = [deep]
    with pytest.raises(ScenarioError, match="at most"):
        scenario_from_dict({"description": deep})


def test_deep_nesting_in_a_file_is_one_line(tmp_path, capsys):
    """Issue 22: deeply nested arrays or inline tables gave RecursionError as an internal error."""
    for k, value in enumerate(["[" * 3000 + "]" * 3000, "{a=" * 3000 + "1" + "}" * 3000]):
        path = tmp_path / f"deep{k}.toml"
        path.write_text(dumps_toml(Scenario().to_dict()) + f"\n[extra]\nx = {value}\n")
        line = one_error_line(capsys, ["check", path])
        assert "nested too deeply" in line
