"""The built-in scenes (coopctrl/scenario/library.py) and their packaging (pyproject.toml): found by name
from a checkout, and shipped in a wheel as the package data of coopctrl.scenarios (issue 21 item 4)."""

from __future__ import annotations

import os
import shutil
import warnings
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


def test_pyproject_lists_every_package_of_the_tree():
    """The packages are listed (coopctrl.scenarios is a mapped folder, which discovery cannot add): every
    package directory of the tree must be in the list, or a wheel would silently lack it."""
    from setuptools import find_packages

    config = tomllib.loads((REPO / "pyproject.toml").read_text())["tool"]["setuptools"]
    data_folders = {"coopctrl.replay.vendor", "plants.arms.data"}  # no __init__.py: listed, as setuptools asks
    expected = set(find_packages(str(REPO), include=["plants*", "coopctrl*"])) | {"coopctrl.scenarios"} | data_folders
    assert set(config["packages"]) == expected
    assert config["package-dir"] == {"coopctrl.scenarios": "scenarios"}


def test_build_puts_every_scene_into_the_package(tmp_path, monkeypatch):
    """setuptools' build_py (the step of `pip wheel` / `pip install .` that lays out the package files)
    on a copy of the project: every scenarios/*.toml lands in coopctrl/scenarios/ of the build."""
    pytest.importorskip("setuptools.config.pyprojecttoml")
    from setuptools.config.pyprojecttoml import apply_configuration
    from setuptools.dist import Distribution

    src = tmp_path / "src"
    src.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy(REPO / name, src / name)
    for name in ("coopctrl", "plants", "scenarios"):
        shutil.copytree(REPO / name, src / name, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    monkeypatch.chdir(src)  # setuptools reads the project relative to the working directory
    dist = apply_configuration(Distribution({"script_name": "setup.py"}), "pyproject.toml")
    build = dist.get_command_obj("build_py")
    build.build_lib = os.fspath(tmp_path / "lib")
    build.ensure_finalized()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        build.run()
    lib = tmp_path / "lib"
    shipped = sorted(p.name for p in (lib / "coopctrl" / "scenarios").glob("*.toml"))
    assert shipped == SCENES
    assert (lib / "coopctrl" / "scenarios" / "__init__.py").is_file()
    # the data folders ship too (the replay's three.js, the named robots' URDF files), declared as setuptools
    # asks: a data folder left out of `packages` is deprecated and would be dropped by a later setuptools
    assert (lib / "coopctrl" / "replay" / "vendor" / "three.min.js").is_file()
    assert sorted(p.name for p in (lib / "plants" / "arms" / "data").glob("*.urdf")) == ["iiwa14.urdf", "panda.urdf",
                                                                                         "ur5e.urdf"]
    deprecated = [str(w.message).split("\n")[0] for w in caught if "as data is deprecated" in str(w.message)]
    assert not deprecated, deprecated
