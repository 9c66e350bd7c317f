"""Beam and matrix elements in scene files (``[[springs]] element = "beam" | "matrix"``) and the
shipped ``flexible_bar_carry``: its first bending mode where beam theory puts it, in the stability
report and in the contact forces, its bent replay, and bad input refused with one line (exit 2)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from coopctrl import cli
from coopctrl.scenario import load_scenario

REPO = Path(__file__).resolve().parent.parent
BAR = REPO / "scenarios" / "flexible_bar_carry.toml"


@pytest.fixture(scope="module")
def bar():
    return load_scenario(BAR)


def _bending_mode_rad_s(sc) -> float:
    """Beam theory: the strip's mass m at its centre on two halves of length L clamped at the grips;
    by symmetry each half is clamped-guided, k = 12 E Iy / L^3, so omega = sqrt(2 k / m)."""
    s = sc.springs[0]
    L = float(np.linalg.norm(np.asarray(sc.arms[0].grasp[:3])))
    return float(np.sqrt(2 * 12 * s.E * s.Iy / L**3 / sc.object.mass))


def test_stability_report_finds_the_bending_mode_where_beam_theory_puts_it(bar):
    from coopctrl.analysis.stability import stability_report

    report = stability_report(bar, integrators=["rk4"], measure=False, closed_loop=False)
    bending = [m for m in report.object_modes if m["coordinate"] == "object_z"]
    assert len(bending) == 1
    # three internal nodes per half: the cubic beam is exact for end loads, so only the loaded
    # state's geometry (a 0.7 mm sag) moves the mode: 1e-3 relative
    assert bending[0]["omega_rad_s"] == pytest.approx(_bending_mode_rad_s(bar), rel=1e-3)
    assert "object_z" in report.table()


def test_the_bending_mode_rings_in_the_contact_forces(bar):
    from scipy.signal import detrend, periodogram

    from coopctrl.simulator import simulate

    result = simulate(load_scenario(BAR, {"simulation.duration": 2.0}))
    assert result.status == "ok"
    Fz = result.F_measured[:, 1, 2]  # the follower's vertical force [N]
    f, P = periodogram(detrend(Fz), fs=1.0 / (result.t[1] - result.t[0]))
    band = (f > 5.0) & (f < 100.0)
    peak_hz = f[band][np.argmax(P[band])]
    # 0.5 Hz bins; the controllers hold the grips but not rigidly: within 10 % of the held-node mode
    assert peak_hz == pytest.approx(_bending_mode_rad_s(bar) / (2 * np.pi), rel=0.1)


def test_the_replay_draws_the_bar_bent(bar):
    from coopctrl.replay.scene_frames import BEAM_POINTS, replay_data
    from coopctrl.simulator import simulate

    result = simulate(load_scenario(BAR, {"simulation.duration": 0.1}))
    data = replay_data(result, bar)
    assert data["beam_exaggeration"] >= 1.0
    frame = data["frames"][3]
    for spring in frame["springs"]:
        pts = np.reshape(spring, (-1, 3))
        assert len(pts) == BEAM_POINTS
        chord = pts[-1] - pts[0]
        off = np.linalg.norm(np.cross(pts - pts[0], chord / np.linalg.norm(chord)), axis=1)
        assert off.max() > 1e-4  # bent, not a straight segment
    assert frame["deformation_mm"] > 0.0


def _run(args, capsys):
    code = cli.main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("override, field", [
    ("springs[0].E=-70e9", "springs[0].E"),
    ("springs[0].A=0", "springs[0].A"),
    ("springs[0].Iy=0", "springs[0].Iy"),
    ("springs[0].internal_nodes=65", "springs[0].internal_nodes"),
    ("springs[0].element='matrix'", "springs[0].element"),
    ("arms[0].grasp=[0,0,0,0,0,0]", "springs[0].pair"),
])
def test_bad_beams_are_refused_naming_the_field(override, field, capsys):
    code, out, err = _run(["check", BAR, "--set", override], capsys)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert field in lines[0]


def _beam_matrix(sc) -> np.ndarray:
    """The bar's half-beam as the plant builds it (its own frame, internal nodes condensed)."""
    from plants.elastic.elastic_system import element_matrix

    el = sc.plant().elastic
    return element_matrix("springs[0]", el.interconnections[0], el.Y_ref[0], el.Y_ref[1])


def _matrix_scene(tmp_path, K):
    text = BAR.read_text()
    start = text.index("[[springs]]")
    end = text.index("[trajectory]")
    rows = ",\n  ".join("[" + ", ".join(repr(float(v)) for v in row) + "]" for row in K)
    springs = "".join(f'[[springs]]\npair = [0, {k}]\nelement = "matrix"\nmatrix = [\n  {rows}\n]\n\n' for k in (1, 2))
    path = tmp_path / "matrix_bar.toml"
    path.write_text(text[:start] + springs + text[end:])
    return path


def test_a_matrix_element_equal_to_the_beam_gives_the_same_plant(bar, tmp_path):
    K = _beam_matrix(bar)
    matrix = load_scenario(_matrix_scene(tmp_path, K))
    Kb, Km = bar.plant().elastic.stiffness_matrix(), matrix.plant().elastic.stiffness_matrix()
    np.testing.assert_allclose(Km, Kb, rtol=0, atol=1e-9 * np.max(np.abs(Kb)))


def test_the_scenes_assembly_is_the_books_with_the_internal_nodes(bar):
    """plant.elastic.stiffness_assembly(): K_e, a_0, a_1 (3 internal nodes per half: 36 columns),
    a and K = a^T K_e a equal to the immobile stiffness the plant linearizes to."""
    el = bar.plant().elastic
    book = el.stiffness_assembly()
    assert book.a_1.shape[1] == 2 * 3 * 6
    K = el.stiffness_matrix()
    np.testing.assert_allclose(book.K, K, rtol=0, atol=1e-9 * np.max(np.abs(K)))
    assert np.linalg.matrix_rank(book.K, tol=1e-9 * np.max(np.abs(K))) == 6 * 2


@pytest.mark.parametrize("damage, words", [
    (lambda K: K + np.triu(np.ones_like(K), 1) * 1e3, "springs[0].matrix"),
    (lambda K: -K, "springs[0].matrix"),
])
def test_bad_matrices_are_refused_naming_the_field(bar, tmp_path, damage, words, capsys):
    K = damage(_beam_matrix(bar))
    code, out, err = _run(["check", _matrix_scene(tmp_path, K)], capsys)
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert words in lines[0]
