"""coopctrl/core's squeeze (squeeze.h; coopctrl._core.pair_squeeze_into): bit for bit the numba kernel the tick runs
(coopctrl.loop.squeeze.pair_squeeze_into), the squeeze and every work array, on seeded wrenches and contact points
for 2, 3 and 4 contacts, planar and spatial, and in its NaN cases (a wrench or a contact not finite, two contacts
coinciding, ill-conditioned pairs)."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.loop.squeeze import pair_squeeze_into, squeeze_workspace

#: (npos, p): planar contacts (x, z) with wrenches (f_x, f_z, n), spatial (x, y, z) with (f, n).
KINDS = {"planar": (2, 3), "spatial": (3, 6)}


def _both(r, F, desired):
    """The numba squeeze and the core's, each on a workspace of its own: (out, work) twice."""
    m, npos = r.shape
    P = m * (m - 1) // 2
    results = []
    for kernel in (pair_squeeze_into, _core.pair_squeeze_into):
        work = squeeze_workspace(m, npos, desired)
        out = np.full(P, -1.0)
        kernel(r, F, *work, out)
        results.append((out, work))
    return results


def _assert_same(results):
    (want, want_work), (got, got_work) = results
    np.testing.assert_array_equal(got, want)
    for field, a, b in zip(want_work._fields, got_work, want_work):
        np.testing.assert_array_equal(a, b, err_msg=field)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("m", [2, 3, 4])
def test_the_squeeze_matches_the_numba_kernel_bit_for_bit(kind, m):
    npos, p = KINDS[kind]
    P = m * (m - 1) // 2
    rng = np.random.default_rng(100 * m + npos)
    for trial in range(20):
        r = rng.uniform(-1.0, 1.0, (m, npos))
        F = rng.normal(scale=20.0, size=(m, p))
        desired = rng.uniform(0.0, 10.0, P) if trial % 2 else np.zeros(P)
        results = _both(r, F, desired)
        _assert_same(results)
        assert np.all(np.isfinite(results[0][0]))


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("m", [2, 3, 4])
def test_the_nan_cases_match_the_numba_kernel(kind, m):
    npos, p = KINDS[kind]
    P = m * (m - 1) // 2
    rng = np.random.default_rng(7 * m + npos)
    r = rng.uniform(-1.0, 1.0, (m, npos))
    F = rng.normal(scale=20.0, size=(m, p))
    desired = rng.uniform(0.0, 10.0, P)
    cases = {}
    for value in (np.nan, np.inf):
        bad_F = F.copy()
        bad_F[m - 1, p - 1] = value  # a moment entry: not used, yet checked
        cases[f"F {value}"] = (r, bad_F)
        bad_r = r.copy()
        bad_r[0, npos - 1] = value
        cases[f"r {value}"] = (bad_r, F)
    coincide = r.copy()
    coincide[m - 1] = coincide[0] + 1e-13
    cases["coinciding contacts"] = (coincide, F)
    collinear = np.outer(np.arange(m, dtype=float), np.ones(npos))  # on one line: the pairs are dependent
    cases["collinear contacts"] = (collinear, F)
    for case, (rc, Fc) in cases.items():
        results = _both(rc, Fc, desired)
        _assert_same(results)
        if case != "collinear contacts":
            assert np.all(np.isnan(results[0][0])), case


def test_one_contact_has_no_pairs():
    out = np.zeros(0)
    work = squeeze_workspace(1, 2, np.zeros(0))
    _core.pair_squeeze_into(np.zeros((1, 2)), np.zeros((1, 3)), *work, out)


def test_bad_arrays_are_named():
    work = squeeze_workspace(3, 2, np.zeros(3))
    with pytest.raises(ValueError, match=r"^F: expected shape"):
        _core.pair_squeeze_into(np.zeros((3, 2)), np.zeros((2, 3)), *work, np.zeros(3))
    with pytest.raises(ValueError, match=r"^E: expected shape \(6, 3\)"):
        _core.pair_squeeze_into(np.zeros((3, 2)), np.zeros((3, 3)), work.desired, np.zeros((5, 3)), *work[2:],
                                np.zeros(3))
