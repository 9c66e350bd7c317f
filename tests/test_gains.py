"""coopctrl/tuning/gains.py: the --set text pastes into `coopctrl run`, and tuned files keep their
comments (units) (issue 14, README truth)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import coopctrl
from coopctrl import cli
from coopctrl.tuning import Gains

REPO = Path(__file__).resolve().parents[1]
PLANAR = REPO / "scenarios" / "planar_two_arm_lift.toml"


def test_printed_set_options_paste_into_the_command_line():
    g = Gains(leader_natural_frequency=55.0, follower_force_loop=False, follower_force_ki=25.0)
    text = str(g.as_set_options())
    assert text == ("--set controllers.leader.natural_frequency=55.0 --set controllers.followers.force_loop=false "
                    "--set controllers.followers.force_ki=25.0")
    assert f"{g.as_set_options()}" == text  # print() shows the same
    assert cli.main(["check", str(PLANAR), *shlex.split(text)]) == 0
    assert list(g.as_set_options()) == shlex.split(text)  # still the argument list


def test_written_file_keeps_comments_and_adds_units(tmp_path):
    g = Gains(leader_natural_frequency=55.0, follower_force_ki=25.0)
    out = g.write_to(PLANAR, tmp_path / "tuned.toml")
    original, written = PLANAR.read_text(), out.read_text()
    comments = [c for c in re.findall(r"#[^\n]*", original)]
    assert comments and all(c in written for c in comments)  # e.g. "# N/m", "# kg m^2"
    assert "natural_frequency = 55.0  # rad/s" in written and "force_ki = 25.0  # 1/s" in written
    s = coopctrl.load_scenario(out)
    assert s.controllers.leader.natural_frequency == 55.0 and s.controllers.followers.force_ki == 25.0
    assert s == coopctrl.load_scenario(PLANAR, g.as_overrides())


def test_missing_table_is_appended_with_units(tmp_path):
    text = PLANAR.read_text()
    stripped = re.sub(r"\[controllers\.leader\][^\[]*", "", text)
    assert "[controllers.leader]" not in stripped
    src = tmp_path / "scene.toml"
    src.write_text(stripped)
    out = Gains(leader_damping_ratio=0.7, leader_natural_frequency=35.0).write_to(src, tmp_path / "tuned.toml")
    written = out.read_text()
    assert "[controllers.leader]" in written and "natural_frequency = 35.0  # rad/s" in written
    assert coopctrl.load_scenario(out).controllers.leader.damping_ratio == 0.7
