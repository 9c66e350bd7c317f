"""The internal-force bases and the pair tensions for any number of contacts (issue 22: eight arms).

``internal_null_basis`` must span the same space as the SVD null space of ``G`` (principal angles at
rounding level) with an orthonormal, hence perfectly conditioned, basis; ``pair_tensions`` must give
the unique tensions where the pairs are independent, the tensions nearest the setpoint where they are
dependent, and NaN (never garbage) where the decomposition is ill-conditioned.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

from coopctrl.load_distribution import grasp_matrix, internal_force_basis, internal_null_basis, pair_tensions
from coopctrl.load_distribution.grasp_matrix import PAIR_KEEP_RTOL, POSITION_DIM, WRENCH_DIM

SPACES = ("planar", "spatial")


def _contacts(rng, m: int, space: str) -> np.ndarray:
    """m contacts spread over a 0.6 m box around the origin (generic: no three collinear)."""
    return rng.uniform(-0.3, 0.3, size=(m, POSITION_DIM[space]))


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", range(2, 9))
def test_null_basis_is_the_svd_null_space_and_orthonormal(space, m):
    rng = np.random.default_rng(100 * m + len(space))
    r = _contacts(rng, m, space)
    r0 = rng.uniform(-0.1, 0.1, size=POSITION_DIM[space])
    G = grasp_matrix(r, r0, space)
    N = internal_null_basis(r, space)
    k = WRENCH_DIM[space]
    assert N.shape == (k * m, k * (m - 1))
    # G N = 0 for any object point; entries of G are at most ~1 (0.4 m arms), so rounding is ~1e-15
    assert np.max(np.abs(G @ N)) < 1e-12
    # orthonormal: condition number 1 up to rounding (a Gram-Schmidt-free Householder QR)
    sv = np.linalg.svd(N, compute_uv=False)
    assert sv[0] / sv[-1] < 1.0 + 1e-9
    # the same subspace as SVD's null space: all principal angles at rounding level (1e-15 rad;
    # 1e-8 leaves room for the angles' sqrt-of-rounding sensitivity near zero)
    Z = scipy.linalg.null_space(G)
    assert Z.shape == N.shape
    assert np.max(scipy.linalg.subspace_angles(N, Z)) < 1e-7


def test_null_basis_refuses_bad_contacts():
    with pytest.raises(ValueError, match="r_contacts"):
        internal_null_basis(np.zeros((3, 3)), "planar")
    with pytest.raises(ValueError, match="r_contacts"):
        internal_null_basis([[0.0, np.nan], [1.0, 0.0]], "planar")


def _rank(E: np.ndarray) -> int:
    sv = np.linalg.svd(E, compute_uv=False)
    return int(np.sum(sv > 1e-9 * sv[0]))


@pytest.mark.parametrize("space", SPACES)
@pytest.mark.parametrize("m", range(2, 9))
def test_pair_tensions_for_any_number_of_contacts(space, m):
    rng = np.random.default_rng(7 * m + len(space))
    r = _contacts(rng, m, space)
    E = internal_force_basis(r, space)
    P = E.shape[1]
    s_true = rng.uniform(0.0, 20.0, P)
    f = E @ s_true
    desired = np.full(P, 5.0)
    s = pair_tensions(E, f, desired)
    assert np.all(np.isfinite(s))
    # whatever the rank, the tensions reproduce the internal force (forces of ~100 N: 1e-9 N is rounding)
    assert np.max(np.abs(E @ s - f)) < 1e-9
    independent = _rank(E) == P  # m = 2, 3; spatial m = 4 (generic)
    assert independent == (m <= 3 or (space == "spatial" and m == 4))
    if independent:
        # unique: the setpoint does not matter
        assert np.max(np.abs(s - s_true)) < 1e-9
        assert np.max(np.abs(pair_tensions(E, f) - s)) < 1e-9
    else:
        # nearest the setpoint: s - desired is orthogonal to the pairs' dependences (null(E))
        V = scipy.linalg.null_space(E)
        assert V.shape[1] == P - _rank(E)
        assert np.max(np.abs(V.T @ (s - desired))) < 1e-9
        # and a load that is exactly the setpoint's is reported as the setpoint (zero error)
        assert np.max(np.abs(pair_tensions(E, E @ desired, desired) - desired)) < 1e-9


def test_pair_tensions_batch_equals_single_samples():
    rng = np.random.default_rng(3)
    Es = np.stack([internal_force_basis(_contacts(rng, 5, "planar"), "planar") for _ in range(4)])
    fs = np.einsum("sij,sj->si", Es, rng.uniform(0, 10, (4, Es.shape[2])))
    batch = pair_tensions(Es, fs, np.full(Es.shape[2], 2.0))
    for i in range(4):
        assert np.allclose(batch[i], pair_tensions(Es[i], fs[i], np.full(Es.shape[2], 2.0)), rtol=0, atol=1e-12)


def test_pair_tensions_are_nan_only_where_a_sample_is_not_finite():
    """A batch with a non-finite sample: NaN tensions for it, the others those of numpy's SVD pseudo-inverse
    (``tests/_pair_tensions_svd.py``; 1e-9 N as in :func:`test_pair_tensions_agree_with_an_svd`), independent and
    dependent pairs."""
    from _pair_tensions_svd import svd_pair_tensions

    rng = np.random.default_rng(8)
    for space, m in (("planar", 3), ("planar", 5), ("spatial", 3), ("spatial", 6)):
        Es = np.stack([internal_force_basis(_contacts(rng, m, space), space) for _ in range(5)])
        fs = np.einsum("sij,sj->si", Es, rng.uniform(0, 10, (5, Es.shape[2]))) + rng.normal(0, 0.1, Es.shape[:2])
        fs[2, 0] = np.nan
        desired = np.full(Es.shape[2], 2.0)
        got = pair_tensions(Es, fs, desired)
        assert np.isnan(got[2]).all() and np.isfinite(got[[0, 1, 3, 4]]).all()
        keep = [0, 1, 3, 4]
        assert np.max(np.abs(got[keep] - svd_pair_tensions(Es[keep], fs[keep], desired))) < 1e-9


def test_ill_conditioned_pairs_give_nan_not_garbage():
    # three contacts 1 m apart, the middle one 1e-8 m off the line: the third pair direction has a
    # relative singular value ~1e-8, between the structural-zero and the kept tolerances
    r = np.array([[-0.5, 0.0], [0.0, 1e-8], [0.5, 0.0]])
    E = internal_force_basis(r, "planar")
    sv = np.linalg.svd(E, compute_uv=False)
    assert 1e-10 < sv[-1] / sv[0] < PAIR_KEEP_RTOL
    s = pair_tensions(E, E @ np.array([5.0, 5.0, 5.0]) + 1e-9, np.full(3, 5.0))
    assert np.all(np.isnan(s))
    # exactly collinear: a structural dependence, decomposed (the squeeze along the line is defined)
    r[1, 1] = 0.0
    E = internal_force_basis(r, "planar")
    s = pair_tensions(E, E @ np.array([5.0, 5.0, 5.0]), np.full(3, 5.0))
    assert np.allclose(s, 5.0, rtol=0, atol=1e-9)


@pytest.mark.parametrize("space", SPACES)
def test_pair_tensions_agree_with_an_svd(space):
    """The compiled one-sided Jacobi of ``pair_tensions`` against numpy's SVD pseudo-inverse
    (``tests/_pair_tensions_svd.py``) on random batches of 2 to 6 contacts (independent and dependent
    pairs): forces of ~100 N, columns conditioned below 1e3, so 1e-9 N is rounding with a wide margin."""
    from _pair_tensions_svd import svd_pair_tensions

    rng = np.random.default_rng(11 + len(space))
    for m in range(2, 7):
        Es = np.stack([internal_force_basis(_contacts(rng, m, space), space) for _ in range(5)])
        fs = rng.normal(0.0, 100.0, (5, Es.shape[1]))
        desired = rng.uniform(0.0, 10.0, Es.shape[2])
        expected = svd_pair_tensions(Es, fs, desired)
        assert np.all(np.isfinite(expected))
        assert np.max(np.abs(pair_tensions(Es, fs, desired) - expected)) < 1e-9
