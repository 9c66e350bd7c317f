"""The result folder of ``coopctrl run --out`` (coopctrl/results/folder.py): it reopens and reruns from
itself alone (issue 21 item 2), it is replaced as one unit (issue 22), and ``--record-every`` thins it
(issue 21 item 5)."""

from __future__ import annotations

import json
import shutil
import zipfile
from pathlib import Path

import numpy as np
import pytest
from _quick_plots import quick_plots  # noqa: F401  (autouse: the plots stubbed)

from coopctrl import cli
from coopctrl.io import dumps_toml

from test_urdf_scenario import _dh_as_urdf, _dh_rows, _scene_data

LIFT = "planar_two_arm_lift"
#: Figures of the summary that are measured on the wall clock (they differ from run to run).
TIMING = ("wall_time_s", "realtime_factor", "startup_s", "qp_solve_time_median_us", "qp_time_share")


def run_cli(args, capsys):
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def _with_meshes(urdf: str, absolute_mesh: Path) -> str:
    """The URDF with a visual mesh on three links: named relative to the URDF, as a ROS package (the
    URDF's folder is ``robots``) and by absolute path."""
    urdf = urdf.replace('<link name="l1">', '<link name="l1"><visual><geometry><mesh filename="meshes/l1.stl"/>'
                        '</geometry></visual>', 1)
    urdf = urdf.replace('<link name="l3">', '<link name="l3"><visual><geometry><mesh '
                        'filename="package://robots/meshes/l3.stl"/></geometry></visual>', 1)
    return urdf.replace('<link name="l2">', f'<link name="l2"><visual><geometry><mesh filename="{absolute_mesh}"/>'
                        '</geometry></visual>', 1)


def test_a_user_urdf_result_reopens_and_reruns_after_its_scene_is_gone(tmp_path, capsys, monkeypatch):
    scene_dir, elsewhere = tmp_path / "scene", tmp_path / "elsewhere"
    (scene_dir / "robots" / "meshes").mkdir(parents=True)
    elsewhere.mkdir()
    (scene_dir / "robots" / "meshes" / "l1.stl").write_bytes(b"solid l1\nendsolid l1\n")
    (scene_dir / "robots" / "meshes" / "l3.stl").write_bytes(b"solid l3\nendsolid l3\n")
    (elsewhere / "l2.obj").write_text("v 0 0 0\n")
    (scene_dir / "robots" / "my_arm.urdf").write_text(_with_meshes(_dh_as_urdf(_dh_rows()), elsewhere / "l2.obj"))
    data = _scene_data(model="urdf", urdf="robots/my_arm.urdf", base_link="base", tip_link="tip",
                       tool=[0.0, 0.0, 0.05, 0.0, -1.5707963267948966, 0.0])
    (scene_dir / "my_scene.toml").write_text(dumps_toml(data))
    monkeypatch.chdir(tmp_path)  # the scene named relative to the working directory, as in the issue
    out = Path("out")
    code, _, err = run_cli(["run", "scene/my_scene.toml", "--set", "simulation.duration=0.01", "-q", "--out", out], capsys)
    assert code == 0, err
    shutil.rmtree(scene_dir)
    shutil.rmtree(elsewhere)

    saved = (out / "scenario.toml").read_text()
    assert 'urdf = "robots/arm1/my_arm.urdf"' in saved
    copied = (out / "robots" / "arm1" / "my_arm.urdf").read_text()
    assert (out / "robots" / "arm1" / "meshes" / "l1.stl").read_bytes() == b"solid l1\nendsolid l1\n"
    assert 'filename="meshes/l1.stl"' in copied and 'filename="meshes/1_l2.obj"' in copied
    assert (out / "robots" / "arm1" / "meshes" / "1_l2.obj").read_text() == "v 0 0 0\n"
    renamed = [line for line in copied.split('"') if line.endswith("_l3.stl")]
    assert renamed and (out / "robots" / "arm1" / renamed[0]).read_bytes() == b"solid l3\nendsolid l3\n"

    (out / "replay.html").unlink()
    code, _, err = run_cli(["view", out], capsys)
    assert code == 0 and err == "", err
    assert (out / "replay.html").is_file()
    code, _, err = run_cli(["run", out / "scenario.toml", "--set", "simulation.duration=0.01", "-q"], capsys)
    assert code == 0, err


def test_rerun_into_the_same_folder_replaces_it_whole(tmp_path, capsys):
    out = tmp_path / "r"
    assert run_cli(["run", LIFT, "--set", "simulation.duration=0.02", "-q", "--out", out], capsys)[0] == 0
    first = json.loads((out / "summary.json").read_text())
    assert run_cli(["run", LIFT, "--set", "simulation.duration=0.03", "-q", "--out", out], capsys)[0] == 0
    second = json.loads((out / "summary.json").read_text())
    assert first["samples"] == 21 and second["samples"] == 31
    with zipfile.ZipFile(out / "result.npz") as z, z.open("t.npy") as f:
        assert np.lib.format.read_array(f).shape == (31,)  # every file of the second run
    assert "duration = 0.03" in (out / "scenario.toml").read_text()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r"]  # no temporary folder beside it


def test_a_failed_second_run_keeps_the_first_whole(tmp_path, capsys, monkeypatch):
    out = tmp_path / "r"
    assert run_cli(["run", LIFT, "--set", "simulation.duration=0.02", "-q", "--out", out], capsys)[0] == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    import coopctrl.results.plots as plots

    def disk_full(*args, **kwargs):
        raise OSError(28, "No space left on device")
    monkeypatch.setattr(plots, "plot_result", disk_full)  # after result.npz of the second run is written
    code, _, err = run_cli(["run", LIFT, "--set", "simulation.duration=0.03", "-q", "--out", out], capsys)
    assert code == 1 and err.strip().startswith("coopctrl: failed: no space left on device writing ")
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r"]


def test_record_every_10_gives_files_ten_times_smaller_and_the_same_metrics(tmp_path, capsys):
    full, thin = tmp_path / "full", tmp_path / "thin"
    common = [LIFT, "--set", "simulation.duration=0.5", "-q"]
    assert run_cli(["run", *common, "--out", full], capsys)[0] == 0
    assert run_cli(["run", *common, "--record-every", "10", "--out", thin], capsys)[0] == 0
    a, b = (json.loads((d / "summary.json").read_text()) for d in (full, thin))
    assert {k: v for k, v in a.items() if k not in TIMING} == {k: v for k, v in b.items() if k not in TIMING}
    # 501 samples against 51 (0, 10, ..., 500): the same columns, a tenth of the rows; the npz also holds
    # the events and the meta text, so its ratio is a little under ten
    for name, low in (("result.csv", 8.5), ("result.npz", 6.0)):
        ratio = (full / name).stat().st_size / (thin / name).stat().st_size
        assert low < ratio < 11.0, (name, ratio)
    from coopctrl.results import SimulationResult

    r = SimulationResult.load(thin)
    assert r.t.shape == (51,) and r.record_every == 10 and r.summary() == b
    np.testing.assert_array_equal(r.t, SimulationResult.load(full).t[::10])


def test_record_every_out_of_range_is_refused_before_any_work(capsys, monkeypatch):
    monkeypatch.setattr(cli.run, "simulate_function", lambda: pytest.fail("simulated a refused run"))
    for value in ("0", "1000001", "2.5"):
        code, out, err = run_cli(["run", LIFT, "--record-every", value], capsys)
        assert code == 2 and out == "" and len(err.strip().splitlines()) == 1, err
        assert "record_every" in err or "--record-every" in err


def test_csv_holds_the_node_poses_and_the_object_velocity(tmp_path, capsys):
    out = tmp_path / "r"
    assert run_cli(["run", LIFT, "--set", "simulation.duration=0.02", "-q", "--out", out], capsys)[0] == 0
    header = (out / "result.csv").read_text().splitlines()[0].split(",")
    for column in ("Y0d_x [m/s]", "Y0d_theta [rad/s]", "node_arm1_x [m]", "node_arm2_theta [rad]"):
        assert column in header, header
    table = np.loadtxt(out / "result.csv", delimiter=",", skiprows=1)
    from coopctrl.scenario import load_scenario
    from coopctrl.scenario.build import initial_state

    scenario = load_scenario(Path(cli.scenarios_dir()) / f"{LIFT}.toml", {"simulation.duration": "0.02"})
    Y = scenario.plant().node_poses(initial_state(scenario)).reshape(3, 3)
    # the first row is the initial state; the csv keeps 10 significant digits
    np.testing.assert_allclose(table[0, [header.index(f"node_arm2_{c} [{u}]") for c, u in
                                         (("x", "m"), ("z", "m"), ("theta", "rad"))]], Y[2], rtol=1e-9, atol=1e-12)


def test_a_passive_result_reopens_though_it_has_no_load_split(tmp_path, capsys):
    """A passive run (controllers off) records no split (F_commanded, F_external, F_internal NaN by design):
    its folder reopens for `coopctrl view`; a controlled result with a NaN split is still refused."""
    from coopctrl.results.folder import open_result_folder

    out = tmp_path / "r"
    assert run_cli(["run", LIFT, "--set", "simulation.duration=0.02", "--set", "controllers.enabled=false", "-q",
                    "--out", out], capsys)[0] == 0
    result, _, _ = open_result_folder(out)
    assert result.energy is not None and np.isnan(result.F_commanded).all()
    assert run_cli(["view", out], capsys)[0] == 0
    controlled = tmp_path / "c"
    assert run_cli(["run", LIFT, "--set", "simulation.duration=0.02", "-q", "--out", controlled], capsys)[0] == 0
    with np.load(controlled / "result.npz") as z:
        arrays = dict(z)
    arrays["F_commanded"][3] = np.nan
    np.savez(controlled / "result.npz", **arrays)
    code, _, err = run_cli(["view", controlled], capsys)
    assert code != 0 and "F_commanded is not finite from t = 0.003 s" in err
