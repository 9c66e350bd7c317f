"""coopctrl.cli.export_mjcf, compare_plants and run --plant: outputs, bad input, and the missing extra."""

from __future__ import annotations

import sys

import pytest

from coopctrl.cli import main


@pytest.fixture
def no_mujoco(monkeypatch):
    """MuJoCo not importable (``import mujoco`` raises ImportError)."""
    monkeypatch.setitem(sys.modules, "mujoco", None)


@pytest.mark.parametrize("argv", [["run", "planar_two_arm_lift", "--plant", "mujoco"],
                                  ["export-mjcf", "planar_two_arm_lift", "OUT.xml"],
                                  ["compare-plants", "planar_two_arm_lift"]])
def test_missing_mujoco_names_the_extra(no_mujoco, argv, tmp_path, capsys):
    argv = [str(tmp_path / a) if a == "OUT.xml" else a for a in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "pip install 'coopctrl[mujoco]'" in err and "Traceback" not in err


def test_export_mjcf_writes_a_model_mujoco_loads(tmp_path, capsys):
    mujoco = pytest.importorskip("mujoco")
    out = tmp_path / "lift.xml"
    assert main(["export-mjcf", "planar_two_arm_lift", str(out)]) == 0
    model = mujoco.MjModel.from_xml_path(str(out))
    assert model.nq == 9 and model.nkey == 1 and model.nsensor == 4 and model.nu == 6
    assert str(out) in capsys.readouterr().out
    assert [p.name for p in tmp_path.iterdir()] == ["lift.xml"]  # no temporary file left


@pytest.mark.parametrize("out, why", [("model.txt", "must end in .xml"), ("missing/model.xml", "does not exist")])
def test_export_mjcf_bad_output_exits_2(tmp_path, capsys, out, why):
    pytest.importorskip("mujoco")
    assert main(["export-mjcf", "planar_two_arm_lift", str(tmp_path / out)]) == 2
    err = capsys.readouterr().err
    assert why in err and len(err.strip().splitlines()) == 1
    assert not any(tmp_path.iterdir())


def test_export_mjcf_contact_point_scene_exits_2(tmp_path, capsys):
    pytest.importorskip("mujoco")
    assert main(["export-mjcf", "contact_points_only", str(tmp_path / "c.xml")]) == 2
    assert "contact_point" in capsys.readouterr().err


def test_run_plant_mujoco_refuses_estimate_error(capsys):
    pytest.importorskip("mujoco")
    assert main(["run", "planar_two_arm_lift", "--plant", "mujoco", "--estimate-error"]) == 2
    assert "--estimate-error" in capsys.readouterr().err


def test_run_plant_mujoco_writes_its_result_folder(tmp_path, capsys):
    pytest.importorskip("mujoco")
    import json

    out = tmp_path / "res"
    code = main(["run", "planar_two_arm_lift", "--plant", "mujoco", "--set", "simulation.duration=0.1",
                 "--out", str(out), "--quiet"])
    assert code == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "ok" and summary["integrator"].startswith("mujoco plant")
    assert (out / "replay.html").is_file() and (out / "result.npz").is_file()
    assert "mujoco plant" in (out / "replay.html").read_text()  # the replay's title line names the plant
    import matplotlib

    matplotlib.use("Agg")
    from coopctrl.results import SimulationResult
    from coopctrl.results.plots import plot_tracking

    fig = plot_tracking(SimulationResult.load(out))
    assert "on the mujoco plant" in fig.get_suptitle()


def test_compare_plants_prints_both_runs_and_their_differences(capsys):
    pytest.importorskip("mujoco")
    import json

    assert main(["compare-plants", "planar_two_arm_lift", "--set", "simulation.duration=0.1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["elastic"]["status"] == out["mujoco"]["status"] == "ok"
    assert out["mujoco"]["integrator"].startswith("mujoco plant")
    assert [d["signal"] for d in out["differences"]][0] == "object position"


@pytest.mark.parametrize("argv, field", [(["run", "two_panda_flip", "--plant", "mujoco"], "trajectory.via"),
                                         (["compare-plants", "contact_points_only"], "arms[0].model")])
def test_scene_mujoco_cannot_run_exits_2_naming_the_field(argv, field, capsys):
    pytest.importorskip("mujoco")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"{field} = " in err and len(err.strip().splitlines()) == 1
