"""plants.elastic.fem against textbook beam results, the direct-stiffness method and rigid-body
invariance. Tolerances: the finite-element results below are exact for the load cases used (cubic
Hermite beams reproduce a tip-loaded cantilever exactly), so they are checked to rounding (1e-9
relative on well-conditioned solves of at most 60 unknowns)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh, null_space

from plants.elastic.fem import (BeamElement, MatrixElement, direct_stiffness, planar_beam_stiffness,
                                spatial_beam_stiffness, stiffness_assembly)

# an aluminium bar, 1 m, 40 x 10 mm
E, G, L = 70e9, 26e9, 1.0
B, H = 0.04, 0.01
A, IY, IZ = B * H, B * H**3 / 12, H * B**3 / 12
J = 0.312 * B * H**3  # torsion constant of a 4:1 rectangle (Roark), only its ratio to G J / L is checked


def _beam(nodes=(0, 1), **kw):
    return BeamElement(nodes, E=E, G=G, A=A, Iy=IY, Iz=IZ, J=J, **kw)


def _solve_fixed(K, fixed, F):
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    x = np.zeros(K.shape[0])
    x[free] = np.linalg.solve(K[np.ix_(free, free)], F[free])
    return x


def _rotation(seed):
    q = np.random.default_rng(seed).normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


@pytest.mark.parametrize("internal", [0, 3])
def test_cantilever_tip_deflection_and_rotation(internal):
    P = 10.0
    K = stiffness_assembly([_beam(internal_nodes=internal)], [[0, 0, 0], [L, 0, 0]]).K
    F = np.zeros(12)
    F[8] = -P  # tip force along -z
    x = _solve_fixed(K, np.arange(6), F)
    assert x[8] == pytest.approx(-P * L**3 / (3 * E * IY), rel=1e-9)
    # the tip turns about +y when it goes down: ry = -dw/dx = +P L^2 / (2 E I)
    assert x[10] == pytest.approx(P * L**2 / (2 * E * IY), rel=1e-9)
    F = np.zeros(12)
    F[7] = P  # along +y: bending about z with Iz
    x = _solve_fixed(K, np.arange(6), F)
    assert x[7] == pytest.approx(P * L**3 / (3 * E * IZ), rel=1e-9)
    assert x[11] == pytest.approx(P * L**2 / (2 * E * IZ), rel=1e-9)


def test_timoshenko_adds_the_shear_term():
    P, kappa = 10.0, 5.0 / 6.0
    K = stiffness_assembly([_beam(shear=True, kappa=kappa)], [[0, 0, 0], [L, 0, 0]]).K
    F = np.zeros(12)
    F[8] = -P
    x = _solve_fixed(K, np.arange(6), F)
    assert x[8] == pytest.approx(-(P * L**3 / (3 * E * IY) + P * L / (kappa * G * A)), rel=1e-9)


def test_axial_and_torsional_stiffness():
    K = spatial_beam_stiffness(E, G, A, IY, IZ, J, L)
    assert K[0, 0] == pytest.approx(E * A / L, rel=1e-15) and K[0, 6] == pytest.approx(-E * A / L, rel=1e-15)
    assert K[3, 3] == pytest.approx(G * J / L, rel=1e-15) and K[3, 9] == pytest.approx(-G * J / L, rel=1e-15)
    Kp = planar_beam_stiffness(E, A, IY, L)
    assert Kp[0, 0] == pytest.approx(E * A / L, rel=1e-15)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_turned_cantilever_bends_the_same(seed):
    """Rotation invariance of the assembly: the same cantilever laid along a seeded direction."""
    R = _rotation(seed)
    P = 10.0
    K = stiffness_assembly([_beam(internal_nodes=2)], [[0, 0, 0], R @ [L, 0, 0]]).K
    from plants.elastic.fem import line_frame
    frame = line_frame(np.zeros(3), R @ [L, 0, 0])
    F = np.zeros(12)
    F[6:9] = -P * frame[:, 2]  # along the element's -z axis
    x = _solve_fixed(K, np.arange(6), F)
    assert float(frame[:, 2] @ x[6:9]) == pytest.approx(-P * L**3 / (3 * E * IY), rel=1e-9)


def _frame_structure(internal):
    """An object node and three contact nodes joined by beams: a closed (indeterminate) frame."""
    P = np.array([[0.0, 0, 0], [0.4, 0, 0.1], [-0.3, 0.3, 0], [-0.1, -0.35, -0.05]])
    elements = [_beam((0, 1), internal_nodes=internal), _beam((0, 2), internal_nodes=internal),
                _beam((0, 3)), _beam((1, 2), internal_nodes=1), _beam((2, 3), shear=True)]
    return elements, P


@pytest.mark.parametrize("internal", [0, 2])
def test_condensation_equals_the_full_system_with_the_internal_nodes_kept(internal):
    elements, P = _frame_structure(internal)
    book = stiffness_assembly(elements, P)
    full, n = direct_stiffness(elements, P)
    F = np.random.default_rng(7).normal(size=n)
    F[:6] = 0.0
    x_book = _solve_fixed(book.K, np.arange(6), F)
    x_full = _solve_fixed(full, np.arange(6), np.r_[F, np.zeros(full.shape[0] - n)])
    np.testing.assert_allclose(x_book, x_full[:n], rtol=1e-9, atol=1e-9 * np.max(np.abs(x_full)))
    if book.a_1.shape[1] == 0:
        np.testing.assert_allclose(book.K, full, rtol=0, atol=1e-9 * np.max(np.abs(full)))
    # (53): the internal nodes carry no force, a_1^T K_e a = 0
    assert np.max(np.abs(book.a_1.T @ book.K_e @ book.a), initial=0.0) <= 1e-9 * np.max(np.abs(book.K_e))


def test_structure_stiffness_is_symmetric_psd_with_exactly_the_rigid_modes():
    elements, P = _frame_structure(2)
    K = stiffness_assembly(elements, P).K
    m = len(P) - 1
    assert np.array_equal(K, K.T)
    w = np.linalg.eigvalsh(K)
    assert w[0] > -1e-9 * w[-1]
    assert np.linalg.matrix_rank(K, tol=1e-9 * w[-1]) == 6 * m
    # the null space is the rigid motions: translations and small rotations about the origin
    rigid = np.zeros((6 * len(P), 6))
    for i, p in enumerate(P):
        rigid[6 * i:6 * i + 3, :3] = np.eye(3)
        rigid[6 * i:6 * i + 3, 3:] = -np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]], [-p[1], p[0], 0]])
        rigid[6 * i + 3:6 * i + 6, 3:] = np.eye(3)
    assert np.max(np.abs(K @ rigid)) <= 1e-9 * w[-1]
    ns = null_space(K, rcond=1e-9)
    assert ns.shape[1] == 6
    # same subspace: projecting the rigid modes on the null space loses nothing
    np.testing.assert_allclose(ns @ (ns.T @ rigid), rigid, atol=1e-8)


def test_a_matrix_element_equals_the_beam_it_holds():
    P = np.array([[0.0, 0, 0], [0.3, 0.4, 0.2]])
    beam = stiffness_assembly([_beam()], P).K
    Kloc = spatial_beam_stiffness(E, G, A, IY, IZ, J, float(np.linalg.norm(P[1])))
    as_matrix = stiffness_assembly([MatrixElement((0, 1), Kloc)], P).K
    np.testing.assert_allclose(as_matrix, beam, rtol=0, atol=1e-12 * np.max(np.abs(beam)))


def test_free_free_beam_frequencies_converge_at_second_order_with_lumped_masses():
    """Planar free-free beam, lumped masses (half at the ends), rotations massless and condensed:
    the first bending frequency against (beta L)^2 sqrt(E I / (rho A L^4)), beta L = 4.730041."""
    rho = 2700.0
    exact = 4.730040745**2 * np.sqrt(E * IY / (rho * A * L**4))
    errors = []
    for n in (8, 16, 32):
        P = np.column_stack((np.linspace(0, L, n + 1), np.zeros(n + 1)))
        elements = [BeamElement((i, i + 1), E=E, G=G, A=A, Iy=IY, Iz=IZ, J=J) for i in range(n)]
        K = stiffness_assembly(elements, P).K
        w = 1 + 3 * np.arange(n + 1)  # transverse (z) displacements
        r = 2 + 3 * np.arange(n + 1)  # rotations: massless, condensed
        Kc = K[np.ix_(w, w)] - K[np.ix_(w, r)] @ np.linalg.solve(K[np.ix_(r, r)], K[np.ix_(r, w)])
        m = np.full(n + 1, rho * A * L / n)
        m[[0, -1]] /= 2
        omega = np.sqrt(np.clip(eigh(Kc, np.diag(m), eigvals_only=True), 0, None))
        first = omega[2]  # two rigid modes (translation, rotation) come first
        errors.append(abs(first - exact) / exact)
    # lumped masses are second order, error about 3 / n^2 here: 0.30 % at n = 32 (measured)
    assert errors[-1] < 5e-3
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all(np.abs(orders - 2.0) < 0.2), orders


@pytest.mark.parametrize("make, match", [
    (lambda: MatrixElement((0, 1), np.arange(144.0).reshape(12, 12)), "symmetric"),
    (lambda: MatrixElement((0, 1), -np.eye(12)), "positive semi-definite"),
    (lambda: BeamElement((0, 1), E=-1.0, G=G, A=A, Iy=IY, Iz=IZ, J=J), "E = -1.0"),
    (lambda: BeamElement((0, 1), E=E, G=G, A=0.0, Iy=IY, Iz=IZ, J=J), "A = 0.0"),
    (lambda: BeamElement((1, 1), E=E, G=G, A=A, Iy=IY, Iz=IZ, J=J), "nodes"),
    (lambda: stiffness_assembly([_beam()], [[0, 0, 0], [0, 0, 0]]), "length"),
    (lambda: stiffness_assembly([_beam((0, 2))], [[0, 0, 0], [1, 0, 0]]), "nodes"),
])
def test_bad_elements_are_refused_naming_the_field(make, match):
    with pytest.raises(ValueError, match=match):
        make()


@pytest.mark.parametrize("scene", ["planar_two_arm_lift", "spatial_three_arm_carry", "gripping_immobile_object"])
def test_a_scenes_springs_assembled_as_the_book_writes_it_give_its_stiffness_matrix(scene):
    from pathlib import Path

    from coopctrl.scenario import load_scenario

    path = Path(__file__).resolve().parents[1] / "scenarios" / f"{scene}.toml"
    elastic = load_scenario(path).plant().elastic
    assembly = elastic.stiffness_assembly()
    np.testing.assert_array_equal(assembly.a, assembly.a_0)  # pairwise springs: statically determinate (49)
    np.testing.assert_allclose(assembly.K, elastic.stiffness_matrix(), rtol=0,
                               atol=1e-12 * np.max(np.abs(elastic.stiffness_matrix())))
