"""Every shipped scenario runs through the CLI; physical bad input is rejected before simulating."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from test_cli import assert_user_error, bad_scene, coopctrl

REPO = Path(__file__).resolve().parent.parent
SHIPPED = sorted(p.stem for p in (REPO / "scenarios").glob("*.toml"))
#: Scenes that are meant to fail: the status they must end with and a word their reason must contain.
#: The buckling scene is refused by pre-flight (statically unstable from t = 0); ``--no-preflight`` shows it.
EXPECTED_FAILURE = {
    "central_spring_buckling": ("diverged", "buckles"),
}
REQUIRED_KEYS = {
    "scenario", "status", "reason", "model", "integrator", "step_s", "control_period_s", "duration_s",
    "wall_time_s", "realtime_factor", "object_position_error_rms_m", "object_position_error_max_m",
    "object_orientation_error_max_rad", "follower_force_error_rms_N", "internal_force_error_rms_N",
    "max_torque_ratio", "qp_solves", "qp_failures", "qp_solve_time_median_us", "energy_drift_rel",
}
MODEL_KEYS = {"arms", "dof_per_arm", "space", "unloaded_state", "state_size"}


def test_the_library_is_complete():
    assert set(SHIPPED) >= {
        "planar_two_arm_lift", "spatial_two_puma_carry", "spatial_three_arm_carry", "gripping_immobile_object",
        "heavy_payload_torque_limits", "stiff_grasp_extreme", "central_spring_buckling", "contact_points_only",
        "euler_singularity",
    }


@pytest.mark.parametrize("name", SHIPPED)
def test_shipped_scenario_runs_briefly(name):
    """0.1 s of each scene (0.1 s is past the buckling scene's failure at ~0.06 s)."""
    expected, needle = EXPECTED_FAILURE.get(name, ("ok", ""))
    if name == "central_spring_buckling":
        refused = coopctrl("run", REPO / "scenarios" / f"{name}.toml", "--set", "simulation.duration=0.1", "--json")
        assert refused.returncode == 1 and refused.stdout == "", refused.stderr
        assert refused.stderr.startswith("coopctrl: failed: pre-flight: ") and needle in refused.stderr
    proc = coopctrl("run", REPO / "scenarios" / f"{name}.toml", "--set", "simulation.duration=0.1", "--json",
                    *(["--no-preflight"] if name == "central_spring_buckling" else []))
    assert proc.returncode == (0 if expected == "ok" else 1), proc.stderr
    assert "Traceback" not in proc.stderr
    summary = json.loads(proc.stdout)
    assert REQUIRED_KEYS <= summary.keys()
    assert MODEL_KEYS <= summary["model"].keys()
    assert summary["status"] == expected
    assert summary["scenario"] == name
    if expected != "ok":
        assert summary["reason"] and len(proc.stderr.splitlines()) == 1
        assert needle in summary["reason"]


def test_run_writes_outputs(tmp_path):
    out = tmp_path / "out"
    proc = coopctrl("run", "planar_two_arm_lift", "--set", "simulation.duration=0.05", "--out", out, "--quiet")
    assert proc.returncode == 0, proc.stderr
    for name in ("result.npz", "result.csv", "summary.json", "object_pose.png", "contact_forces.png",
                 "joint_torques.png", "qp_solve_times.png"):
        assert (out / name).stat().st_size > 0, name
    assert not [p for p in out.iterdir() if p.name.startswith(".") or p.suffix == ".tmp"]


@pytest.mark.parametrize(
    "mutate, field, needle",
    [
        # a grasp outside the arm's reach (the leader's node 2 m away from its base)
        (lambda d: d["arms"][0].update(grasp=[-2.0, 0.0, 0.0]), "arms[0].grasp", "within reach"),
        # a torque limit below the arm's own gravity load
        (lambda d: d["arms"][1].update(tau_max=[5.0, 5.0, 5.0]), "arms[1].tau_max", "gravity load"),
        (lambda d: d["arms"][1].update(node_mass=-0.3), "arms[1].node_mass", ""),
        (lambda d: d["springs"][1].update(stiffness=float("inf")), "springs[1].stiffness", ""),
        (lambda d: d["springs"][0].update(damping="lots"), "springs[0].damping", ""),
        (lambda d: d["object"].update(mass=-2.0), "object.mass", ""),
        (lambda d: d["simulation"].update(substeps=0), "simulation.substeps", ""),
    ],
)
def test_bad_physics_is_rejected_before_simulating(tmp_path, mutate, field, needle):
    path = bad_scene(tmp_path, mutate)
    for command in ("check", "run"):
        assert_user_error(coopctrl(command, path), field, needle)
