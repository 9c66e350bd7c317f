"""``coopctrl show``: the resolved scenario as TOML that loads back to an equal scenario."""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from coopctrl.cli import main
from coopctrl.scenario import Scenario, load_scenario

REPO = Path(__file__).resolve().parents[1]
SCENES = sorted((REPO / "scenarios").glob("*.toml"))


def _show(*argv: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(["show", *argv]) == 0
    return out.getvalue()


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_show_loads_back_to_an_equal_scenario(tmp_path, path):
    text = _show(str(path))
    again = tmp_path / "shown.toml"
    again.write_text(text, encoding="utf-8")
    assert load_scenario(again) == load_scenario(path)
    data = tomllib.loads(text)
    # every default filled in: each section the scenario has is written out, springs included
    assert {"scene", "object", "arms", "springs", "trajectory", "load_distribution", "controllers",
            "sensors", "simulation"} <= set(data)
    assert "pose" not in data["object"]  # redundant with trajectory.via[0].pose, so left out


def test_show_default_scene_and_overrides(tmp_path):
    text = _show("--set", "simulation.duration=0.5", "--set", "springs[1].stiffness=3e4")
    path = tmp_path / "d.toml"
    path.write_text(text, encoding="utf-8")
    shown = load_scenario(path)
    assert shown == load_scenario(None, {"simulation.duration": 0.5, "springs[1].stiffness": 3e4})
    assert shown != Scenario()
    assert "stiffness = 30000.0  # N/m" in text


def test_show_bad_input_exits_2_with_one_line():
    proc = subprocess.run([sys.executable, "-m", "coopctrl", "show", "planar_two_arm_lift", "--set", "object.mass=1e-300"],
                          capture_output=True, text=True, cwd=REPO, timeout=120)
    assert proc.returncode == 2 and proc.stdout == ""
    assert len(proc.stderr.strip().splitlines()) == 1 and "object.mass" in proc.stderr


def test_show_writes_no_unit_after_a_switch_and_never_minus_zero(tmp_path):
    """``torque_limits = false`` is a switch, not a torque: no ``# N m`` after it (nor after any boolean);
    a pose entered as -0.0 is written 0.0 (equal when loaded back)."""
    text = _show(str(REPO / "scenarios" / "planar_two_arm_lift.toml"), "--set", "arms[0].base=[-0.6, -0.0, -0.0]")
    lines = text.splitlines()
    assert "torque_limits = false" in lines
    switches = [ln for ln in lines if ln.split("#")[0].rstrip().endswith(("= true", "= false"))]
    assert switches and all("#" not in ln for ln in switches), switches
    assert "base = [-0.6, 0.0, 0.0]  # m, rad" in lines
    assert "-0.0," not in text and "-0.0]" not in text
    path = tmp_path / "shown.toml"
    path.write_text(text, encoding="utf-8")
    assert load_scenario(path) == load_scenario(REPO / "scenarios" / "planar_two_arm_lift.toml",
                                                {"arms[0].base": [-0.6, -0.0, -0.0]})
