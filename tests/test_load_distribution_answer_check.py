"""The QP answer check and binding families (coopctrl/core/qp_answer_check.h, bound in ``coopctrl._core``; the rule
in :mod:`coopctrl.load_distribution.answer_check`): written once, compiled, run by the compiled tick and by
``LoadDistribution``.

Issue 18: the check was written twice (numpy in ``LoadDistribution``, loops in the kernel). The one
compiled definition is checked here against numpy formulas written from the documented rule and against
answers of an independent solver (proxsuite).
"""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl._core import answer_ok, answer_tolerance, answer_violation, binding_families
from coopctrl.load_distribution import LoadDistribution, LoadDistributionConfig
from coopctrl.load_distribution.answer_check import FAMILY_MIN_GRIP
from coopctrl.load_distribution.load_distribution import ANSWER_TOLERANCE_OF_LOAD

#: Relative agreement of a compiled reduction with numpy's: sums of a dozen products of order 10 in
#: another order; rounding gives about 1e-15 relative.
REL = 1e-12


def _stacked(rng, k=3, n_in=4, n=6):
    """A random stacked problem ``lo <= M x <= hi``: ``k`` balance rows, then inequality rows with an
    infinite bound on each side somewhere."""
    M = rng.normal(size=(k + n_in, n))
    x = rng.normal(0.0, 5.0, n)
    y = M @ x
    lo = np.concatenate([y[:k] + rng.normal(0.0, 1e-3, k), y[k:] - rng.uniform(-1.0, 2.0, n_in)])
    hi = np.concatenate([lo[:k], y[k:] + rng.uniform(-1.0, 2.0, n_in)])
    lo[k] = -np.inf
    hi[k + 1] = np.inf
    return M, lo, hi, x, k


def _numpy_violation(M, lo, hi, x):
    y = M @ x
    return max(np.max(lo - y), np.max(y - hi)), np.max(np.abs(y))


def _numpy_tolerance(lo, hi, k, scale, eps_abs, rho):
    """The documented tolerance with the load cap: ``min(100 eps (1 + s), rho max(1, |w|, |l|, |u|))``."""
    bounds = np.concatenate([lo[:k], lo[k:][np.isfinite(lo[k:])], hi[k:][np.isfinite(hi[k:])]])
    return min(100.0 * eps_abs * (1.0 + scale), rho * max(1.0, np.max(np.abs(bounds))))


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_violation_and_tolerance_follow_the_documented_rule(seed):
    rng = np.random.default_rng(seed)
    M, lo, hi, x, k = _stacked(rng)
    viol, scale = answer_violation(M, lo, hi, x, x.shape[0])
    ref_viol, ref_scale = _numpy_violation(M, lo, hi, x)
    assert abs(viol - ref_viol) <= REL * ref_scale and abs(scale - ref_scale) <= REL * ref_scale
    for eps_abs in (1e-9, 1e-3, 1.0):  # the solver's tolerance binds, then the load's cap
        tol = answer_tolerance(lo, hi, k, np.inf, scale, eps_abs, ANSWER_TOLERANCE_OF_LOAD)
        assert abs(tol - _numpy_tolerance(lo, hi, k, scale, eps_abs, ANSWER_TOLERANCE_OF_LOAD)) <= REL * tol
    # a clean answer is not capped: the solver's own tolerance
    assert answer_tolerance(lo, hi, k, 0.0, scale, 1.0, ANSWER_TOLERANCE_OF_LOAD) == 100.0 * (1.0 + scale)


def _planar_split(solver: str, min_grip: float, squeeze: float = 0.0):
    """Two planar contacts at +-0.25 m holding 2 kg; ``min_grip`` [N] along the inward normals, the desired
    ``squeeze`` [N]."""
    cfg = LoadDistributionConfig(min_grip=min_grip, solver=solver, squeeze=squeeze)
    ld = LoadDistribution(cfg, "planar", 2)
    r = np.array([[0.25, 0.0], [-0.25, 0.0]])
    split = ld.solve(r, np.zeros(2), np.array([0.0, 2.0 * 9.81, 0.0]), normals=-r)
    return ld, split


def test_an_independent_solvers_answer_passes_and_a_wrong_one_fails():
    """proxsuite's answer passes the check; moved off the balance by ten times the tolerance, or made
    NaN, it fails."""
    ld, split = _planar_split("proxsuite", 15.0)
    pb = ld.problem
    F = np.ascontiguousarray(split.F.reshape(-1))
    eps = ld.config.eps_abs
    assert answer_ok(pb.M, pb.lo, pb.hi, F, pb.n, pb.k, eps, ANSWER_TOLERANCE_OF_LOAD)
    viol, scale = answer_violation(pb.M, pb.lo, pb.hi, F, pb.n)
    tol = answer_tolerance(pb.lo, pb.hi, pb.k, viol, scale, eps, ANSWER_TOLERANCE_OF_LOAD)
    off = F.copy()
    off[1] += 10.0 * tol  # one more vertical force: the balance is violated by that much
    assert not answer_ok(pb.M, pb.lo, pb.hi, off, pb.n, pb.k, eps, ANSWER_TOLERANCE_OF_LOAD)
    bad = F.copy()
    bad[0] = np.nan
    assert not answer_ok(pb.M, pb.lo, pb.hi, bad, pb.n, pb.k, eps, ANSWER_TOLERANCE_OF_LOAD)


def test_binding_families_name_the_active_rows_of_an_independent_solver():
    """A 15 N minimum grip with no squeeze binds (the pseudo-inverse split grips with 0 N): proxsuite's
    multipliers give the min_grip bit, the rows are at their bound, and the compiled solver agrees. With a
    20 N desired squeeze the grip is 20 N and nothing binds."""
    ld, split = _planar_split("proxsuite", 15.0)
    pb = ld.problem
    assert split.binding == ("min_grip",)
    F = split.F.reshape(-1)
    assert np.max(np.abs(pb.C @ F - 15.0)) <= 1e-6 * 15.0  # both grip rows at the bound (proxsuite's 1e-9 N)
    z = ld.solver.solve(pb).z
    mask = binding_families(pb.g, np.ascontiguousarray(z), 0, pb.n, pb.n_in, pb.m, 0, -1, pb.n_facets, -1)
    assert mask == FAMILY_MIN_GRIP
    assert _planar_split("compiled", 15.0)[1].binding == ("min_grip",)
    for solver in ("proxsuite", "compiled"):
        assert _planar_split(solver, 15.0, squeeze=20.0)[1].binding == ()
