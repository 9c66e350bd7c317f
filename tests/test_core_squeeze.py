"""coopctrl/core's squeeze (squeeze.h; coopctrl._core.pair_squeeze_into, which the tick records per tick) against
numpy's SVD pair tensions (``tests/_pair_tensions_svd.py``) on the force rows of the squeeze basis, on seeded wrenches
and contact points for 2, 3 and 4 contacts, planar and spatial, and in its NaN cases (a wrench or a contact not
finite, two contacts coinciding); collinear contacts (dependent pairs) give the tensions nearest the setpoint. (The
kernel was checked bit for bit against the numba kernel it replaced when it was ported; the golden records lock the
recorded squeeze since; tests/test_loop_squeeze.py checks a run's squeeze.)"""

from __future__ import annotations

import numpy as np
import pytest

from _pair_tensions_svd import svd_pair_tensions
from coopctrl import _core
from coopctrl.load_distribution import internal_force_basis
from coopctrl.loop.squeeze import squeeze_workspace

#: (npos, p): planar contacts (x, z) with wrenches (f_x, f_z, n), spatial (x, y, z) with (f, n).
KINDS = {"planar": (2, 3), "spatial": (3, 6)}
#: Agreement with the SVD reference [N]: pseudo-inverses of well-conditioned pair columns, forces of ~20 N: rounding
#: gives about 1e-13 N; a wrong formula gives newtons.
AGREE_N = 1e-9


def _squeeze(r, F, desired):
    m, npos = r.shape
    out = np.full(m * (m - 1) // 2, -1.0)
    _core.pair_squeeze_into(r, F, *squeeze_workspace(m, npos, desired), out)
    return out


def _reference(kind, r, F, desired):
    """The SVD pair tensions of the wrenches' force entries on the squeeze basis's force rows."""
    npos, p = KINDS[kind]
    E = internal_force_basis(r, kind)
    Ef = E[np.arange(E.shape[0]) % p < npos]
    return svd_pair_tensions(Ef, F[:, :npos].ravel(), desired)


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("m", [2, 3, 4])
def test_the_squeeze_is_the_svd_pair_tensions(kind, m):
    npos, p = KINDS[kind]
    P = m * (m - 1) // 2
    rng = np.random.default_rng(100 * m + npos)
    for trial in range(20):
        r = rng.uniform(-1.0, 1.0, (m, npos))
        F = rng.normal(scale=20.0, size=(m, p))
        desired = rng.uniform(0.0, 10.0, P) if trial % 2 else np.zeros(P)
        got = _squeeze(r, F, desired)
        want = _reference(kind, r, F, desired)
        assert np.all(np.isfinite(want))
        assert np.max(np.abs(got - want)) <= AGREE_N


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("m", [2, 3, 4])
def test_the_nan_cases(kind, m):
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
    for case, (rc, Fc) in cases.items():
        assert np.all(np.isnan(_squeeze(rc, Fc, desired))), case
    collinear = np.outer(np.arange(m, dtype=float), np.ones(npos))  # on one line: the pairs are dependent
    got = _squeeze(collinear, F, desired)
    want = _reference(kind, collinear, F, desired)
    np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
    assert np.nanmax(np.abs(got - want), initial=0.0) <= AGREE_N
