"""The squeeze the kernel records per tick (``coopctrl.loop.squeeze``) and its summary metric.

Issue 22 (eight arms): the virtual-linkage decomposition was singular for four or more contacts, and
an eight-arm run reported an internal-force error of 188 N with no contact force above 25 N. The
squeeze is now the pair tensions nearest the setpoint (unique for two and three contacts, where it
is the old ``E^+ f_int``), and the summary never reports a metric from an ill-conditioned sample.

Issue 18: the squeeze is computed per tick in the compiled kernel (one-sided Jacobi rotations of the
pair columns, no grasp matrix) instead of by a batched SVD after the run. :func:`_reference` below is
that former post-processing, kept as the independent reference: the grasp matrix's pseudo-inverse for
the internal part and the SVD pair tensions (``tests/_pair_tensions_svd.py``: the public
:func:`~coopctrl.load_distribution.grasp_matrix.pair_tensions` now runs the kernel's compiled Jacobi).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from coopctrl import load_scenario, simulator
from coopctrl.load_distribution import grasp_matrix, internal_force_basis, internal_null_basis
from coopctrl.loop.squeeze import squeeze_series
from coopctrl.results.summary import summarize
from coopctrl.scenario import build

from _pair_tensions_svd import svd_pair_tensions

SCENES = Path(__file__).resolve().parent.parent / "scenarios"

#: Largest difference allowed between the kernel's squeeze and the reference [N]: both are
#: pseudo-inverses of the same well-conditioned pair columns (forces of at most a few hundred N,
#: condition numbers below 1e3): rounding gives about 1e-12 N; a wrong formula gives whole newtons.
AGREE_N = 1e-9


def _reference(F, r_contacts, r_object, space: str, desired=None) -> np.ndarray:
    """The squeeze per sample by the former post-processing: ``f_int = F - G^+ G F`` with ``G`` the
    grasp matrix about ``r_object``, then the SVD pair tensions ``s_des + E^+ (f_int - E s_des)``."""
    F = np.asarray(F, dtype=float)
    r = np.asarray(r_contacts, dtype=float)
    N, m, k = F.shape
    P = m * (m - 1) // 2
    f_int = np.empty((N, m * k))
    E = np.empty((N, m * k, P))
    for n in range(N):
        G = grasp_matrix(r[n], r_object[n], space)
        f = F[n].reshape(-1)
        with np.errstate(invalid="ignore"):  # a non-finite force: NaN, as the former code
            f_int[n] = f - np.linalg.pinv(G) @ (G @ f)
        with np.errstate(divide="ignore", invalid="ignore"):  # coincident contacts: NaN, as the former code
            t = [(r[n, j] - r[n, i]) / np.linalg.norm(r[n, j] - r[n, i]) for i in range(m) for j in range(i + 1, m)]
        E[n] = 0.0
        col = 0
        for i in range(m):
            for j in range(i + 1, m):
                E[n, k * i:k * i + r.shape[2], col] = t[col]
                E[n, k * j:k * j + r.shape[2], col] = -t[col]
                col += 1
    return svd_pair_tensions(E, f_int, desired)


def _random_run(rng, N: int, m: int, space: str = "planar"):
    npos, k = (2, 3) if space == "planar" else (3, 6)
    r = rng.uniform(-0.3, 0.3, size=(N, m, npos))
    r0 = rng.uniform(-0.05, 0.05, size=(N, npos))
    F = rng.normal(0.0, 10.0, size=(N, m, k))
    return F, r, r0


@pytest.mark.parametrize("m", [2, 3])
def test_two_and_three_contacts_keep_the_old_squeeze(m):
    """For two and three contacts the pairs are independent: the squeeze is the old ``E^+ f_int``,
    whatever the setpoint (to 1e-9 N: pseudo-inverses of forces of ~10 N, rounding about 1e-12 N)."""
    rng = np.random.default_rng(m)
    F, r, r0 = _random_run(rng, 50, m)
    s = squeeze_series(F, r, np.full(m * (m - 1) // 2, 5.0))
    for n in range(50):
        G = grasp_matrix(r[n], r0[n], "planar")
        f = F[n].reshape(-1)
        f_int = f - np.linalg.pinv(G) @ (G @ f)
        old = np.linalg.pinv(internal_force_basis(r[n], "planar")) @ f_int
        assert np.max(np.abs(s[n] - old)) < 1e-9


@pytest.mark.parametrize("space", ["planar", "spatial"])
@pytest.mark.parametrize("m", [2, 3, 4, 5, 6, 8])
def test_the_tick_squeeze_is_the_svd_formula_for_any_number_of_contacts(space, m):
    """Random contacts and wrenches, a random setpoint: dependent pairs (planar m >= 4, spatial
    m >= 5, coplanar spatial contacts), collinear contacts (a structural rank drop) and the transposed
    decomposition (planar m >= 6: more pairs than force rows) give the reference's tensions."""
    rng = np.random.default_rng(100 * m + len(space))
    F, r, r0 = _random_run(rng, 40, m, space)
    if space == "spatial" and m == 4:
        r[:20, :, 2] = 0.1  # coplanar: 5 independent pairs of 6
    if m == 3:
        r[3, 2] = r[3, 0] + 0.4 * (r[3, 1] - r[3, 0])  # collinear: rank 2 of 3, exactly dependent
    desired = rng.uniform(0.0, 10.0, m * (m - 1) // 2)
    expected = _reference(F, r, r0, space, desired)
    got = squeeze_series(F, r, desired)
    assert np.all(np.isfinite(expected))  # the draws are well conditioned: a comparison of numbers
    assert np.max(np.abs(got - expected)) < AGREE_N


def test_ill_conditioned_or_coincident_contacts_give_nan_as_the_reference():
    """Three planar contacts 1e-8 m off a line (singular values 1e-8 apart: between the rank
    tolerances), two coincident ones, a non-finite force: NaN in both, the other samples equal."""
    rng = np.random.default_rng(7)
    F, r, r0 = _random_run(rng, 6, 3)
    r[1] = [[0.0, 0.0], [0.2, 0.0], [0.1, 1e-8]]
    r[2, 1] = r[2, 0]
    F[4, 1, 2] = np.inf
    expected = _reference(F, r, r0, "planar", np.zeros(3))
    got = squeeze_series(F, r, np.zeros(3))
    bad = [1, 2, 4]
    assert np.all(np.isnan(expected[bad])) and np.all(np.isnan(got[bad]))
    good = np.delete(np.arange(6), bad)
    assert np.max(np.abs(got[good] - expected[good])) < AGREE_N


def test_coincident_contacts_give_nan_and_no_metric():
    """A sample whose contacts coincide has no squeeze, and the summary then reports no internal-force
    error (it says where the squeeze is undefined), never a number computed from it."""
    scenario = load_scenario(SCENES / "planar_two_arm_lift.toml", {"simulation.duration": 0.005})
    result = simulator.simulate(scenario)
    assert result.status == "ok" and summarize(result)["internal_force_error_unavailable"] is None
    r = result.Y_nodes[:, :, :2].copy()
    r[2, 1] = r[2, 0]  # sample 2: the two contacts coincide
    s = squeeze_series(result.F_measured, r, result.squeeze_desired)
    assert np.all(np.isnan(s[2])) and np.all(np.isfinite(np.delete(s, 2, axis=0)))
    why = summarize(dataclasses.replace(result, squeeze=s))["internal_force_error_unavailable"]
    assert f"undefined at 1 of {len(result.t)} samples (first at t = {result.t[2]:.4g} s)" in why


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


@pytest.fixture(scope="module")
def eight_arm_result(tmp_path_factory):
    return simulator.simulate(load_scenario(_eight_arm_scene(tmp_path_factory.mktemp("eight") / "eight.toml")))


def test_eight_arms_report_an_internal_force_error_consistent_with_the_forces(eight_arm_result):
    result = eight_arm_result
    summary = summarize(result)
    assert summary["status"] == "ok"
    assert summary["internal_force_error_unavailable"] is None
    reported = summary["internal_force_error_rms_N"]
    # independent recomputation: the internal part by the orthonormal null-space basis (not G^+), its
    # error against the desired linkage forces, decomposed by a minimum-norm least squares
    F, r, desired = result.F_measured, result.Y_nodes[:, :, :2], result.squeeze_desired
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


def _run(scenario):
    loop = simulator.closed_loop(scenario)
    rec = loop.run(build.initial_state(scenario), scenario.simulation.duration)
    nz, p, npos = loop.plant.nz, loop.plant.p, loop.npos
    return rec, rec["x"][:, nz - p:nz - p + npos], loop.space, loop.squeeze_desired


@pytest.mark.parametrize("name, overrides", [
    ("planar_two_arm_lift", {"sensors.forces.noise_std": 0.5}),  # planar, noisy force readings
    ("spatial_three_arm_carry", {}),  # three arms: three independent pairs
    ("spatial_two_puma_carry", {}),
])
def test_the_recorded_squeeze_is_the_svd_formula_on_scenes(name, overrides):
    """Every recorded tick: the kernel's squeeze equals the former SVD/pinv post-processing of the
    recorded measured wrenches at the recorded contacts, to :data:`AGREE_N`."""
    scenario = load_scenario(SCENES / f"{name}.toml", {"simulation.duration": 0.1, **overrides})
    rec, r0, space, desired = _run(scenario)
    assert rec["status"] == "ok" and rec["squeeze"].shape == (len(rec["t"]), desired.shape[0])
    expected = _reference(rec["F_measured"], rec["r_contacts"], r0, space, desired)
    assert np.all(np.isfinite(expected))
    assert np.max(np.abs(rec["squeeze"] - expected)) < AGREE_N
    assert np.max(np.abs(expected)) > 1.0  # a squeeze of newtons is compared, not zeros


def test_eight_arm_squeeze_is_the_svd_formula_per_tick(eight_arm_result):
    """Eight planar arms (28 pairs, 13 independent: the transposed decomposition, nearest the setpoint)."""
    result = eight_arm_result
    expected = _reference(result.F_measured, result.Y_nodes[:, :, :2], result.Y0[:, :2], "planar",
                          result.squeeze_desired)
    assert np.max(np.abs(result.squeeze - expected)) < AGREE_N
