"""The squeeze of a whole run (``coopctrl.loop.squeeze.squeeze_series``) and its summary metric.

Issue 22 (eight arms): the virtual-linkage decomposition was singular for four or more contacts, and
an eight-arm run reported an internal-force error of 188 N with no contact force above 25 N. The
squeeze is now the pair tensions nearest the setpoint (unique for two and three contacts, where it
is the old ``E^+ f_int``), and the summary never reports a metric from an ill-conditioned sample.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from coopctrl import simulator
from coopctrl.load_distribution import grasp_matrix, internal_force_basis, internal_null_basis
from coopctrl.loop.squeeze import squeeze_series
from coopctrl.results.summary import _internal_force_error, summarize
from coopctrl.scenario import load_scenario


def _random_run(rng, N: int, m: int, k: int = 3):
    r = rng.uniform(-0.3, 0.3, size=(N, m, 2))
    r0 = rng.uniform(-0.05, 0.05, size=(N, 2))
    F = rng.normal(0.0, 10.0, size=(N, m, k))
    return F, r, r0


@pytest.mark.parametrize("m", [2, 3])
def test_two_and_three_contacts_keep_the_old_squeeze(m):
    """For two and three contacts the pairs are independent: the squeeze is the old ``E^+ f_int``,
    whatever the setpoint (to 1e-9 N: both are SVD-based pseudo-inverses of forces of ~10 N)."""
    rng = np.random.default_rng(m)
    F, r, r0 = _random_run(rng, 50, m)
    s = squeeze_series(F, r, r0, "planar", np.full(m * (m - 1) // 2, 5.0))
    for n in range(50):
        G = grasp_matrix(r[n], r0[n], "planar")
        f = F[n].reshape(-1)
        f_int = f - np.linalg.pinv(G) @ (G @ f)
        old = np.linalg.pinv(internal_force_basis(r[n], "planar")) @ f_int
        assert np.max(np.abs(s[n] - old)) < 1e-9


def test_coincident_contacts_give_nan_and_no_metric():
    rng = np.random.default_rng(5)
    F, r, r0 = _random_run(rng, 4, 3)
    r[2, 1] = r[2, 0]  # sample 2: two contacts coincide
    s = squeeze_series(F, r, r0, "planar", np.zeros(3))
    assert np.all(np.isnan(s[2])) and np.all(np.isfinite(np.delete(s, 2, axis=0)))
    rms, why = _internal_force_error(s, np.zeros(3), np.arange(4) * 1e-3)
    assert rms is None and "undefined at 1 of 4 samples (first at t = 0.002 s)" in why


def _eight_arm_scene(path) -> str:
    """Eight planar contact points on a 0.15 m circle around a 2 kg disc (contact points: the
    cheapest arms), 0.05 s of a small lift, 5 N desired squeeze per pair."""
    lines = ['name = "eight_contact_points"', "[scene]", 'space = "planar"', 'unloaded_state = "mobile"',
             "gravity = 9.81", "[object]", "mass = 2.0", "inertia = [0.02]", "pose = [0.0, 0.4, 0.0]"]
    for i in range(8):
        a = 2 * math.pi * i / 8
        c, s = math.cos(a), math.sin(a)
        lines += ["[[arms]]", 'model = "contact_point"', f'role = "{"leader" if i == 0 else "follower"}"',
                  f"base = [{0.6 * c!r}, {0.4 + 0.6 * s!r}, {a + math.pi!r}]",
                  f"grasp = [{0.15 * c!r}, {0.15 * s!r}, {a + math.pi!r}]", "node_mass = 0.3", "node_inertia = [1e-3]"]
    for i in range(8):
        lines += ["[[springs]]", f"pair = [0, {i + 1}]", "stiffness = 2e4", "torsion = 200.0", "damping = 60.0",
                  "torsion_damping = 0.5", 'element = "offset"']
    lines += ["[trajectory]", "via = [{ time = 0.0, pose = [0.0, 0.4, 0.0] }, { time = 1.0, pose = [0.05, 0.45, 0.1] }]",
              "[load_distribution]", 'split = "pseudo_inverse"', "squeeze = 5.0",
              "[controllers.leader]", "natural_frequency = 40.0", "damping_ratio = 1.0",
              "[controllers.followers]", "force_loop = true", "force_kp = 1.0", "force_ki = 40.0",
              "natural_frequency = 60.0", "damping_ratio = 1.0",
              "[simulation]", "duration = 0.05", "control_period = 0.001", 'integrator = "rk4"', "substeps = 1",
              "seed = 0", "max_deformation = 0.05"]
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_eight_arms_report_an_internal_force_error_consistent_with_the_forces(tmp_path, monkeypatch):
    seen = {}

    def spy(F, r_contacts, r_object, space, desired=None):
        seen.update(F=np.array(F), r=np.array(r_contacts), desired=np.array(desired))
        return squeeze_series(F, r_contacts, r_object, space, desired)

    monkeypatch.setattr(simulator, "squeeze_series", spy)
    result = simulator.simulate(load_scenario(_eight_arm_scene(tmp_path / "eight.toml")))
    summary = summarize(result)
    assert summary["status"] == "ok"
    assert summary["internal_force_error_unavailable"] is None
    reported = summary["internal_force_error_rms_N"]
    # independent recomputation: the internal part by the orthonormal null-space basis (not G^+), its
    # error against the desired linkage forces, decomposed by a minimum-norm least squares
    F, r, desired = seen["F"], seen["r"], seen["desired"]
    assert desired.shape == (28,) and np.all(desired == 5.0)
    errors = []
    for n in range(F.shape[0]):
        Nb = internal_null_basis(r[n], "planar")
        f = F[n].reshape(-1)
        E = internal_force_basis(r[n], "planar")
        errors.append(np.linalg.lstsq(E, Nb @ (Nb.T @ f) - E @ desired, rcond=1e-8)[0])
    expected = float(np.sqrt(np.mean(np.square(errors))))
    # both are pseudo-inverses of the same well-conditioned (rank 13 of 28) decomposition: rounding
    assert reported == pytest.approx(expected, rel=1e-6, abs=1e-9)
    # and it is on the scale of the forces (the singular decomposition reported 188 N with no contact
    # force above 25 N): an error in pair tensions cannot exceed the largest contact force by far
    assert reported <= float(np.max(np.abs(F)))
    assert np.all(np.isfinite(result.squeeze))
