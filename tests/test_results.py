"""Tests of coopctrl.results with a synthetic SimulationResult (made-up arrays)."""

from __future__ import annotations

import json
import math
import os

import numpy as np
import pytest

import coopctrl.io.atomic as atomic_module
from coopctrl.io import atomic_write
from coopctrl.results import SimulationResult, summary_table

REQUIRED_KEYS = {
    "scenario", "status", "reason", "model", "integrator", "step_s", "control_period_s", "duration_s",
    "wall_time_s", "realtime_factor", "object_position_error_rms_m", "object_position_error_max_m",
    "object_orientation_error_max_rad", "follower_force_error_rms_N", "internal_force_error_rms_N",
    "max_torque_ratio", "qp_solves", "qp_failures", "qp_solve_time_median_us", "energy_drift_rel",
}


def synthetic(space="planar", m=2, n=200, *, limits=True, conserving=False, nan=False, status="ok") -> SimulationResult:
    rng = np.random.default_rng(0)
    p = 3 if space == "planar" else 6
    dof = 3 if space == "planar" else 6
    t = np.linspace(0.0, 0.199, n)
    nominal = np.zeros((n, p))
    nominal[:, 1 if p == 3 else 2] = 0.5 + 0.1 * t
    Y0 = nominal + 1e-3 * rng.standard_normal((n, p))
    F_cmd = rng.standard_normal((n, m, p))
    F_meas = F_cmd + 0.1 * rng.standard_normal((n, m, p))
    pairs = m * (m - 1) // 2
    tau = 5.0 * rng.standard_normal((n, m * dof))
    energy = 10.0 + 1e-4 * rng.standard_normal(n)
    solve = 50e-6 * (1.0 + rng.random(n))
    status_list = ["solved"] * n
    status_list[5] = "PROXQP_MAX_ITER_REACHED"
    if nan:
        Y0[-1] = np.nan
        solve[3] = np.inf
    return SimulationResult(
        scenario="synthetic",
        space=space,
        t=t,
        x=rng.standard_normal((n, 2 * (m * dof + p))),
        tau=tau,
        tau_max=np.full(m * dof, 20.0) if limits else None,
        Y0=Y0,
        Y0_nominal=nominal,
        F_measured=F_meas,
        F_commanded=F_cmd,
        F_external=0.8 * F_cmd,
        F_internal=0.2 * F_cmd,
        squeeze=5.0 + 0.1 * rng.standard_normal((n, pairs)),
        squeeze_desired=np.full(pairs, 5.0),
        qp_status=status_list,
        qp_iterations=rng.integers(1, 10, n),
        qp_solve_time_s=solve,
        events=[(0.1, "qp_failed", "max iterations"), (0.15, "saturation", "arm 1 joint 2")],
        status=status,
        reason="" if status == "ok" else "deformation 0.06 m > 0.05 m at t = 0.19 s",
        model={"arms": m, "dof_per_arm": [dof] * m, "space": space, "unloaded_state": "mobile", "state_size": 2 * (m * dof + p)},
        integrator="rk4",
        step_s=1e-3,
        control_period_s=1e-3,
        duration_s=0.2,
        wall_time_s=0.05,
        energy=energy,
        kinetic_energy=np.abs(rng.standard_normal(n)),
        energy_conserving=conserving,
        leader=0,
        followers=list(range(1, m)),
    )


@pytest.mark.parametrize("space, m", [("planar", 2), ("spatial", 2), ("spatial", 3)])
def test_summary_keys_and_values(space, m):
    r = synthetic(space, m)
    s = r.summary()
    assert REQUIRED_KEYS <= set(s)
    json.dumps(s, allow_nan=False)
    assert s["qp_solves"] == r.t.size and s["qp_failures"] == 1
    assert s["realtime_factor"] == pytest.approx(0.199 / 0.05)
    assert 0 < s["object_position_error_rms_m"] <= s["object_position_error_max_m"] < 0.01
    assert 0 < s["object_orientation_error_max_rad"] < 0.01
    assert s["follower_force_error_rms_N"] == pytest.approx(0.1 * math.sqrt(2 if space == "planar" else 3), rel=0.2)
    assert s["internal_force_error_rms_N"] == pytest.approx(0.1, rel=0.2)
    assert s["max_torque_ratio"] == pytest.approx(np.max(np.abs(r.tau)) / 20.0)
    assert 50 <= s["qp_solve_time_median_us"] <= 100
    assert s["energy_drift_rel"] is None
    assert s["model"]["arms"] == m


def test_energy_drift_when_conserving():
    r = synthetic(conserving=True)
    s = r.summary()
    E = r.energy
    assert s["energy_drift_rel"] == pytest.approx(np.max(np.abs(E - E[0])) / abs(E[0]))


def test_no_limits_gives_null_ratio():
    assert synthetic(limits=False).summary()["max_torque_ratio"] is None


def test_no_nan_in_json(tmp_path):
    r = synthetic(nan=True)
    r.wall_time_s = 0.0
    s = r.summary()
    text = json.dumps(s, allow_nan=False)
    assert "NaN" not in text and "Infinity" not in text
    assert s["realtime_factor"] is None
    assert s["object_position_error_max_m"] is None
    r.save(tmp_path)
    loaded = json.loads((tmp_path / "summary.json").read_text())
    assert loaded["object_position_error_max_m"] is None


def test_summary_table_is_aligned_text():
    table = summary_table(synthetic(status="diverged").summary())
    lines = table.splitlines()
    assert any(line.startswith("status") and "diverged" in line for line in lines)
    assert any("reason" in line for line in lines)
    assert "mm" in table and "us" in table
    starts = {line.index(line.split("  ")[-1].strip()) for line in lines if "  " in line}
    assert len(starts) == 1


def test_save_writes_three_files_and_loads_back(tmp_path):
    r = synthetic("spatial", 3)
    out = tmp_path / "run"
    paths = r.save(out)
    assert sorted(p.name for p in paths) == ["result.csv", "result.npz", "summary.json"]
    header = (out / "result.csv").read_text().splitlines()[0].split(",")
    # units in the header; arms and joints numbered from 1 alike (contact k is arm k)
    assert header[0] == "t [s]" and "Y0_psi [rad]" in header and "F_measured_arm3_mz [N m]" in header
    assert "tau_arm3_j6 [N m]" in header and "q_arm1_j1 [rad]" in header and "qd_arm2_j4 [rad/s]" in header
    assert "squeeze_1_3 [N]" in header and "squeeze_desired_2_3 [N]" in header
    table = np.loadtxt(out / "result.csv", delimiter=",", skiprows=1)
    assert table.shape == (r.t.size, len(header))
    back = SimulationResult.load(out)
    np.testing.assert_array_equal(back.F_measured, r.F_measured)
    assert back.qp_status == r.qp_status and back.events == r.events and back.model == r.model
    assert back.summary() == r.summary()
    assert not [p for p in os.listdir(out) if p.endswith(".tmp")]


def test_shape_mismatch_names_field():
    r = synthetic()
    with pytest.raises(ValueError, match="F_commanded"):
        SimulationResult(**{**r.__dict__, "F_commanded": r.F_commanded[:, :1]})
    with pytest.raises(ValueError, match="status"):
        SimulationResult(**{**r.__dict__, "status": "exploded"})


# ---------------------------------------------------------------------- atomic writing
def test_atomic_write_failure_leaves_target_unchanged(tmp_path):
    target = tmp_path / "summary.json"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_write(target, "w") as f:
            f.write("new, half written")
            raise RuntimeError("crash mid-write")
    assert target.read_text() == "old"
    assert os.listdir(tmp_path) == ["summary.json"]


def test_atomic_write_interrupt_leaves_no_file(tmp_path):
    target = tmp_path / "result.csv"
    with pytest.raises(KeyboardInterrupt):
        with atomic_write(target, "w") as f:
            f.write("partial")
            raise KeyboardInterrupt
    assert os.listdir(tmp_path) == []


def test_save_crash_mid_write_keeps_old_files(tmp_path, monkeypatch):
    r = synthetic()
    r.save(tmp_path)
    before = (tmp_path / "result.npz").read_bytes()

    def failing_replace(src, dst):
        raise OSError("disk full")

    monkeypatch.setattr(atomic_module.os, "replace", failing_replace)
    with pytest.raises(OSError):
        synthetic(m=3).save(tmp_path)
    assert (tmp_path / "result.npz").read_bytes() == before
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


def test_save_crash_in_serialiser_leaves_no_target(tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise MemoryError("boom")

    monkeypatch.setattr(np, "savez_compressed", broken)
    with pytest.raises(MemoryError):
        synthetic().save(tmp_path)
    assert os.listdir(tmp_path) == []


def test_atomic_write_binary(tmp_path):
    with atomic_write(tmp_path / "a.bin", "wb") as f:
        f.write(b"\x00\x01")
    assert (tmp_path / "a.bin").read_bytes() == b"\x00\x01"


# ---------------------------------------------------------------------- plots
@pytest.mark.parametrize("space, m, limits", [("planar", 2, True), ("spatial", 3, False)])
def test_plot_writes_nonempty_pngs(tmp_path, space, m, limits):
    paths = synthetic(space, m, limits=limits).plot(tmp_path)
    names = sorted(p.name for p in paths)
    assert names == ["contact_forces.png", "joint_torques.png", "object_pose.png", "qp_solve_times.png"]
    for p in paths:
        data = p.read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 1000
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


def test_object_quaternion_is_the_rotation_of_Y0_continuous_through_pitch_90():
    """result.object_quaternion (issue 20): the ZYX rotation of Y0 as (w, x, y, z), checked against scipy's
    Rotation, unit, and continuous (no sign jump) along a turn of the pitch from 0 to 120 deg; planar: None."""
    from dataclasses import replace

    from scipy.spatial.transform import Rotation

    r = synthetic("spatial", 2)
    n = r.t.size
    Y0 = r.Y0.copy()
    Y0[:, 3] = np.linspace(-3.0, 3.0, n)           # psi through +-pi, where the angle would jump
    Y0[:, 4] = np.linspace(0.0, np.radians(120.0), n)  # theta through 90 deg
    Y0[:, 5] = np.linspace(0.5, -0.5, n)
    q = replace(r, Y0=Y0).object_quaternion
    ref = Rotation.from_euler("ZYX", Y0[:, 3:6]).as_quat()[:, [3, 0, 1, 2]]  # scipy is (x, y, z, w)
    assert q.shape == (n, 4)
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", q, ref)), 1.0, atol=1e-12)  # the same rotation, +-q
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-12)
    # continuity: neighbouring samples differ by a small rotation, never by a sign flip (|dq| ~ 2 here)
    assert np.max(np.linalg.norm(np.diff(q, axis=0), axis=1)) < 0.1
    assert synthetic("planar", 2).object_quaternion is None


def test_object_quaternion_is_the_recorded_rotation_of_a_run_in_charts_and_it_is_saved(tmp_path):
    """A run in rotation charts records the object's rotation exactly (result.object_rotation): object_quaternion
    returns it (sign-continuous) rather than the rotation of Y0, and result.npz keeps it."""
    from dataclasses import replace

    from coopctrl.results.storage import load_result, save_result
    from coopctrl.trajectory.quaternion import exp

    r = synthetic("spatial", 2)
    n = r.t.size
    half = np.linspace(0.0, 1.2, n)[:, None] * np.array([0.0, 1.0, 0.0])  # a turn about y through 137 deg
    rotation = exp(2.0 * half)
    rotation[1::2] *= -1.0  # the sign of a recorded quaternion is free: every other one flipped
    charted = replace(r, object_rotation=rotation)
    q = charted.object_quaternion
    np.testing.assert_array_equal(np.abs(q), np.abs(rotation))  # the recorded numbers, signs made continuous
    assert np.max(np.linalg.norm(np.diff(q, axis=0), axis=1)) < 0.1
    assert not np.allclose(np.abs(np.einsum("ij,ij->i", q, r.object_quaternion)), 1.0)  # not Y0's rotation
    save_result(charted, tmp_path)
    np.testing.assert_array_equal(load_result(tmp_path).object_rotation, rotation)
    with pytest.raises(ValueError, match=r"object_rotation has shape \(\d+, 3\), expected \(N, 4\)"):
        replace(r, object_rotation=rotation[:, :3])
