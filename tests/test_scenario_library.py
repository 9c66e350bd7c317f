"""The built-in scenes (coopctrl/scenario/library.py) and their packaging (pyproject.toml): found by name
from a checkout, and shipped in a wheel as the package data of coopctrl.scenarios (issue 21 item 4)."""

from __future__ import annotations

import fnmatch
import tomllib
from pathlib import Path

import pytest

import coopctrl
from coopctrl import cli
from coopctrl.errors import ScenarioError
from coopctrl.scenario import library

REPO = Path(__file__).resolve().parent.parent
SCENES = sorted(p.name for p in (REPO / "scenarios").glob("*.toml"))


def test_checkout_finds_the_scenarios_folder():
    assert library.builtin_dir() == (REPO / "scenarios").resolve()
    assert library.builtin_names() == tuple(Path(n).stem for n in SCENES)
    assert len(SCENES) >= 10  # the shipped scenes (a guard against globbing the wrong folder)


def test_load_scenario_takes_a_name_as_the_cli_does():
    by_name = coopctrl.load_scenario("spatial_two_puma_carry")
    by_path = coopctrl.load_scenario(REPO / "scenarios" / "spatial_two_puma_carry.toml")
    assert by_name == by_path and by_name.name == "spatial_two_puma_carry"
    assert coopctrl.load_scenario("spatial_two_puma_carry.toml") == by_path


def test_a_file_in_the_working_directory_wins_over_a_builtin_name(tmp_path, monkeypatch):
    (tmp_path / "spatial_two_puma_carry").write_text((REPO / "scenarios" / "planar_two_arm_lift.toml").read_text())
    monkeypatch.chdir(tmp_path)
    assert coopctrl.load_scenario("spatial_two_puma_carry").space == "planar"


@pytest.mark.parametrize("name", ["no_such_scene", "../scenarios/planar_two_arm_lift", "scenarios/"])
def test_unknown_names_are_missing_files(name, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # nothing of these names here
    assert library.builtin_path(name) is None
    with pytest.raises(ScenarioError, match="file not found"):
        coopctrl.load_scenario(name)


def test_list_prints_every_shipped_scene(capsys):
    assert cli.main(["list"]) == 0
    listed = [line.split()[0] for line in capsys.readouterr().out.splitlines()]
    assert listed == [Path(n).stem for n in SCENES]


def test_pyproject_ships_every_package_of_the_tree():
    """scikit-build-core ships every file under the folders pyproject.toml maps to packages: coopctrl, plants and
    the scenes of scenarios/ as coopctrl.scenarios (a mapped folder, which no discovery finds). The wheel leaves
    out only the C++ sources of the compiled core (built into its modules), never a scene, a robot or the replay's
    page."""
    config = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["scikit-build"]
    assert config["wheel"]["packages"] == {"coopctrl": "coopctrl", "coopctrl/scenarios": "scenarios",
                                           "plants": "plants"}
    excluded = config["wheel"]["exclude"]
    shipped = [*REPO.glob("scenarios/*.toml"), *REPO.glob("plants/arms/data/*.urdf"),
               REPO / "coopctrl" / "replay" / "page.html", REPO / "coopctrl" / "replay" / "vendor" / "three.min.js"]
    assert sorted(p.name for p in REPO.glob("scenarios/*.toml")) == SCENES
    for path in shipped:
        rel = path.relative_to(REPO).as_posix()
        assert path.is_file(), rel
        assert not any(fnmatch.fnmatch(rel, pattern.replace("**", "*")) for pattern in excluded), rel
