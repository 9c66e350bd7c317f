"""SimulationResult.to_pandas() and .to_time_response(): shapes, names and units (issue 14), and the
same names and units as result.csv."""

from __future__ import annotations

import numpy as np
import pytest

from test_results import synthetic

pd = pytest.importorskip("pandas", reason="pandas is the optional extra coopctrl[pandas] (in the test extra)")


@pytest.mark.parametrize("space, m", [("planar", 2), ("spatial", 3)])
def test_to_pandas_names_units_and_values(space, m):
    r = synthetic(space, m)
    df = r.to_pandas()
    dof, p = (3, 3) if space == "planar" else (6, 6)
    joints = m * dof
    pairs = m * (m - 1) // 2
    # pose + nominal + velocity, q, qd, tau, four wrench families, squeeze + desired, qp iterations/time,
    # energy (no node poses: the synthetic result has none); spatial: the object's quaternion (4 columns)
    expected_columns = 3 * p + 3 * joints + 4 * m * p + 2 * pairs + 3 + (4 if space == "spatial" else 0)
    assert df.shape == (r.t.size, expected_columns)
    np.testing.assert_array_equal(df.index.to_numpy(), r.t)
    units = df.attrs["units"]
    assert set(units) == set(df.columns) | {"t"} and units["t"] == "s"
    last = f"arm{m}_j{dof}"
    assert units[f"tau_{last}"] == "N m" and units[f"q_{last}"] == "rad" and units[f"qd_{last}"] == "rad/s"
    assert units["Y0_x"] == "m" and units["Y0_theta"] == "rad" and units["squeeze_1_2"] == "N"
    assert units["Y0d_x"] == "m/s" and units["Y0d_theta"] == "rad/s"
    np.testing.assert_array_equal(df["Y0d_x"], r.x[:, 2 * joints + p])  # x = col(q, Y0, q', Y0')
    moment = "my" if space == "planar" else "mz"
    assert units[f"F_measured_arm{m}_fx"] == "N" and units[f"F_measured_arm{m}_{moment}"] == "N m"
    # values are the result's, in the documented numbering (arm k = contact k, 1-based)
    np.testing.assert_array_equal(df[f"tau_arm{m}_j{dof}"], r.tau[:, -1])
    np.testing.assert_array_equal(df[f"F_commanded_arm{m}_fx"], r.F_commanded[:, m - 1, 0])
    np.testing.assert_array_equal(df["q_arm1_j1"], r.x[:, 0])
    assert df.attrs["scenario"] == "synthetic" and df.attrs["status"] == "ok" and "world frame" in df.attrs["wrench_frame"]


def test_to_pandas_units_in_names_match_the_csv(tmp_path):
    r = synthetic("spatial", 2)
    r.save(tmp_path)
    header = (tmp_path / "result.csv").read_text().splitlines()[0].split(",")
    df = r.to_pandas(units_in_names=True)
    assert [df.index.name, *df.columns] == header
    back = pd.read_csv(tmp_path / "result.csv", index_col=0)
    assert list(back.columns) == list(df.columns)
    np.testing.assert_allclose(back.to_numpy(), df.to_numpy(), rtol=1e-9)  # csv keeps 10 significant digits


@pytest.mark.parametrize("space, m", [("planar", 2), ("spatial", 3)])
def test_to_time_response_named_signals(space, m):
    import control

    r = synthetic(space, m)
    resp = r.to_time_response()
    assert isinstance(resp, control.TimeResponseData)
    dof, p = (3, 3) if space == "planar" else (6, 6)
    n = r.t.size
    assert resp.inputs.shape == (m * dof, n) and resp.states.shape == (2 * (m * dof + p), n)
    assert resp.input_labels[0] == "tau_arm1_j1" and resp.input_labels[-1] == f"tau_arm{m}_j{dof}"
    assert resp.state_labels[0] == "q_arm1_j1" and resp.state_labels[m * dof] == "Y0_x"
    np.testing.assert_array_equal(resp.time, r.t)
    np.testing.assert_array_equal(resp.states, r.x.T)
    k = resp.output_labels.index(f"F_measured_arm{m}_fx")
    np.testing.assert_array_equal(resp.outputs[k], r.F_measured[:, m - 1, 0])
    assert len(set(resp.output_labels)) == len(resp.output_labels)
    labels = resp.output_labels + resp.input_labels + resp.state_labels
    assert set(resp.units) == set(labels)
    assert resp.units["tau_arm1_j1"] == "N m" and resp.units["Y0d_x"] == "m/s" and resp.units["Y0_nominal_z"] == "m"
    assert resp.sysname == "synthetic" and resp.success


def test_failed_run_is_marked_in_the_time_response():
    resp = synthetic("planar", 2, status="diverged").to_time_response()
    assert not resp.success and "deformation" in resp.message
