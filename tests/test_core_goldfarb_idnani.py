"""coopctrl/core/goldfarb_idnani (the compiled core's QP solver, coopctrl._core.gi_solve) on seeded random
load-distribution QPs, feasible, infeasible and degenerate, cold and warm started: each kind's verdict (known by
construction), the KKT conditions at rounding level, warm and cold starts giving the same answer, iteration limits;
special cases with known verdicts; the same answers as proxsuite, daqp and quadprog; the ``"compiled"`` backend
warm starting the core as a direct call does; and its arguments checked once at the binding.

The random problems are those of ``tests/test_goldfarb_idnani.py`` (its generator: the loop's QP with every
inequality family, each kind's verdict known by construction, with a margin). The solver was checked bit for bit
against the numba kernel it replaced (whole workspace included) when it was ported; the golden records lock the
loop's splits since.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from test_goldfarb_idnani import (
    BATCHES,
    FACETS,
    FORCE_TOL,
    KINDS,
    TOL,
    _accept,
    _binding,
    _seed,
    generate,
    solve_daqp,
    solve_proxsuite,
    solve_quadprog,
)

from coopctrl import _core
from coopctrl.load_distribution.goldfarb_idnani import (
    INFEASIBLE,
    MAX_ITER,
    NOT_CONVEX,
    SOLVED,
    WARM_ACTIVE,
    gi_workspace,
)


def _solve(args, ws, new_H, tol=TOL, max_iter=1000):
    """The core's solve on ``ws``; a solved answer is checked: the KKT stationarity ``H x + g + M^T z = 0`` at
    rounding level (1e-9 (1 + |g|_inf): an active-set answer is exact up to rounding) and every row within its
    bounds (``_accept``). Returns (status, iterations, x, z)."""
    H, g, M, lo, hi, n_eq = args
    n, rows = H.shape[0], M.shape[0]
    x, z = np.full(n, 7.0), np.full(rows, 7.0)
    status, iters = _core.gi_solve(H, g, M, lo, hi, n_eq, x, z, ws, new_H, tol, max_iter)
    if status == SOLVED:
        assert np.abs(H @ x + g + M.T @ z).max() <= 1e-9 * (1 + np.abs(g).max())
        assert _accept(x, M, lo, hi)
        assert _core.gi_active_inequalities(ws, n_eq) == int(np.sum(z[n_eq:] != 0.0))
    return status, iters, x, z


@pytest.mark.parametrize("space", ["planar", "spatial"])
@pytest.mark.parametrize("kind", KINDS)
def test_gi_solve_cold_and_warm_started_meets_the_kkt_conditions(space, kind):
    """For m = 1 to 4 arms, 40 problems each: cold, warm started from the previous problem's active set (wrong
    rows dropped, then iterations), and once more from its own (the fast path, the same answer to 1e-9 N); every
    kind's verdict is the construction's."""
    statuses, fast = set(), 0
    for m in (1, 2, 3, 4):
        b = generate(space, m, kind, 40, _seed(space, m, kind) + 31)
        n, rows, k = b["n"], b["M"].shape[1], b["k"]
        ws = gi_workspace(n, rows)
        for j in range(40):
            args = (b["P"][j], b["g"][j], b["M"][j], b["lo"][j], b["hi"][j], k)
            if j % 3 == 0:
                ws[3][WARM_ACTIVE] = 0
            status, _, x, _ = _solve(args, ws, True)
            statuses.add(status)
            again, iters, y, _ = _solve(args, ws, False)
            assert again == status
            if status == SOLVED:
                assert np.abs(y - x).max() <= 1e-9 * (1 + np.abs(x).max())
            fast += status == SOLVED and iters == 0
    assert statuses == ({SOLVED} if kind in ("feasible", "degenerate") else {INFEASIBLE})
    if kind in ("feasible", "degenerate"):
        assert fast >= 100  # the second solve of a solved problem mostly takes the fast path


@pytest.mark.parametrize("space", ["planar", "spatial"])
@pytest.mark.parametrize("m", [2, 3, 4])
def test_warm_started_sequence_with_iteration_limits_agrees_with_cold_solves(space, m):
    """Along 200 slowly varying problems (load, preferred split and torque bounds drift; H factorised once,
    then kept), the core warm started from its previous solve agrees with a cold solve (1e-9 N); an iteration
    limit of 3 on every fifth step may give MAX_ITER, and the next step goes on from that state."""
    b = generate(space, m, "degenerate", 1, _seed(space, m, "degenerate") + 7)
    rng = np.random.default_rng(2000 + m)
    k, n = b["k"], b["n"]
    P, g0, M, lo0, hi0 = b["P"][0], b["g"][0], b["M"][0], b["lo"][0], b["hi"][0]
    dg, dw = rng.normal(size=n) * 2.0, rng.normal(size=k) * 1.0
    ws = gi_workspace(n, M.shape[0])
    statuses = []
    for step in range(200):
        t = step * 1e-2
        g = g0 + math.sin(3 * t) * dg
        lo, hi = lo0.copy(), hi0.copy()
        lo[:k] += math.sin(2 * t) * dw
        hi[:k] = lo[:k]
        lo[k + m:] += 0.3 * math.sin(t)
        hi[k + m:] += 0.3 * math.sin(t)
        limited = step % 5 == 4
        status, _, x, _ = _solve((P, g, M, lo, hi, k), ws, step == 0, max_iter=3 if limited else 1000)
        statuses.append(status)
        assert status in ((SOLVED, MAX_ITER) if limited else (SOLVED,))
        if status == SOLVED:
            cold, _, y, _ = _solve((P, g, M, lo, hi, k), gi_workspace(n, M.shape[0]), True)
            assert cold == SOLVED and np.abs(y - x).max() <= 1e-9 * (1 + np.abs(y).max())
    assert statuses.count(SOLVED) >= 160


def test_special_cases_give_their_known_verdicts():
    """Not positive definite H, a NaN in M or a bound, a non-finite g, a zero row whose bound excludes 0,
    consistent and inconsistent dependent equalities, only equalities, only inequalities, infinite bounds,
    a dense H and iteration limits 0 and 1: each case's known status (a solved one meets the KKT conditions)."""
    rng = np.random.default_rng(5)
    n = 3
    eye = np.eye(n)
    box = np.vstack([eye, np.zeros((1, n))])
    lo_box, hi_box = np.array([-1.0, -1.0, -1.0, 1.0]), np.array([1.0, 1.0, 1.0, np.inf])
    A = rng.normal(size=(n, n))
    dense = A @ A.T + 0.5 * eye
    dep = np.array([[1.0, 1.0, 0.0], [2.0, 2.0, 0.0], [0.0, 0.0, 1.0]])
    cases = [
        (np.diag([1.0, -1.0, 1.0]), np.ones(n), box, lo_box, hi_box, 0, NOT_CONVEX),
        (eye, np.ones(n), box, lo_box, hi_box, 0, INFEASIBLE),
        (eye, 2 * np.ones(n), box, np.array([-1.0, -1.0, -1.0, 0.0]), hi_box, 0, SOLVED),
        (eye, np.ones(n), np.where(box == 1.0, np.nan, box), np.zeros(4), hi_box, 0, NOT_CONVEX),
        (eye, np.ones(n), box, np.array([np.nan, -1.0, -1.0, 0.0]), hi_box, 0, NOT_CONVEX),
        (eye, np.array([np.inf, 0.0, 0.0]), box, np.zeros(4), hi_box, 0, NOT_CONVEX),
        (eye, np.array([1.0, 2.0, 3.0]), dep, np.array([1.0, 2.0, 0.0]), np.array([1.0, 2.0, 0.0]), 3, SOLVED),
        (eye, np.array([1.0, 2.0, 3.0]), dep, np.array([1.0, 3.0, 0.0]), np.array([1.0, 3.0, 0.0]), 3,
         INFEASIBLE),
        (dense, rng.normal(size=n), rng.normal(size=(5, n)), np.full(5, -0.1), np.full(5, 0.1), 0, SOLVED),
        (dense, rng.normal(size=n) * 10, rng.normal(size=(4, n)), np.array([0.5, -np.inf, -0.2, -np.inf]),
         np.array([0.5, 0.3, np.inf, np.inf]), 1, SOLVED),
    ]
    for H, g, M, lo, hi, n_eq, want in cases:
        status, _, _, _ = _solve((H, g, M, lo, hi, n_eq), gi_workspace(n, M.shape[0]), True)
        assert status == want, (M, lo, hi, status)
    b = generate("spatial", 3, "feasible", 1, 77)
    args = (b["P"][0], b["g"][0], b["M"][0], b["lo"][0], b["hi"][0], b["k"])
    limits = []
    for max_iter in (0, 1, 1000):
        limits.append(_solve(args, gi_workspace(b["n"], b["M"].shape[1]), True, max_iter=max_iter)[0])
    assert limits == [MAX_ITER, MAX_ITER, SOLVED]


@pytest.mark.parametrize("space", ["planar", "spatial"])
def test_gi_solve_matches_proxsuite_daqp_quadprog(space):
    """An independent check of the core itself, 60 problems per (m, kind) batch: the verdict of the
    construction and of each reference, forces within FORCE_TOL = 1e-6 N of each (proxsuite at eps_abs 1e-9 is
    about 1e-7 N off the exact optimum, daqp and quadprog closer), the same binding families and a KKT
    residual at rounding level (1e-9 (1 + |g|_inf): an active-set answer is exact up to rounding)."""
    mismatches, solved = [], 0
    for sp, m, kind in BATCHES:
        if sp != space:
            continue
        b = generate(space, m, kind, 60, _seed(space, m, kind) + 53)
        k, n, rows, fams = b["k"], b["n"], b["M"].shape[1], b["families"]
        ws = gi_workspace(n, rows)
        x, z = np.zeros(n), np.zeros(rows)
        expect = kind in ("feasible", "degenerate")
        for j in range(60):
            P, g, M, lo, hi = b["P"][j], b["g"][j], b["M"][j], b["lo"][j], b["hi"][j]
            ws[3][WARM_ACTIVE] = 0
            status, _ = _core.gi_solve(P, g, M, lo, hi, k, x, z, ws, True, TOL, 1000)
            ok = status == SOLVED
            tag = (space, m, kind, j)
            assert ok == expect and (ok or status == INFEASIBLE), (tag, status)
            if ok:
                assert np.abs(P @ x + g + M.T @ z).max() <= 1e-9 * (1 + np.abs(g).max()), tag
                assert _accept(x, M, lo, hi), tag
                solved += 1
            for name, ref in (("proxsuite", solve_proxsuite), ("daqp", solve_daqp), ("quadprog", solve_quadprog)):
                rok, rx, rz = ref(P, g, M, lo, hi, k)
                if rok != ok:
                    mismatches.append((tag, name, "verdict", ok, rok))
                elif ok and np.abs(rx - x).max() > FORCE_TOL:
                    mismatches.append((tag, name, "force", np.abs(rx - x).max()))
                elif ok and _binding(rz, fams, g) != _binding(z[k:], fams, g):
                    mismatches.append((tag, name, "binding"))
    assert not mismatches, mismatches[:10]
    assert solved == 4 * 2 * 60


def test_compiled_backend_solves_with_the_core():
    """``LoadDistribution(solver="compiled")`` answers with the core: along 12 problems, each warm started from
    the last, its split ``F`` is the core's answer, bit for bit, on the problem it assembled, the core called
    directly and warm started the same way (one workspace carried along, ``P`` factorised on the first solve)."""
    from coopctrl.load_distribution import LoadDistribution, LoadDistributionConfig

    m = 3
    b = generate("spatial", m, "feasible", 12, 4243)
    cfg = LoadDistributionConfig(solver="compiled", min_grip=1.0, friction_coefficient=0.8, friction_facets=FACETS,
                                 torque_limits=True)
    ld = LoadDistribution(cfg, "spatial", m)
    ref_ws = None
    warm = 0
    for j in range(12):
        args = (b["r"][j], b["r0"][j], b["w"][j], b["nrm"][j], list(b["J"][j]), list(b["bias"][j]),
                list(b["tau_max"][j]))
        split = ld.solve(*args)
        problem = ld.problem
        n, rows = problem.M.shape[1], problem.M.shape[0]
        first = ref_ws is None
        if first:
            ref_ws = gi_workspace(n, rows)
        x, z = np.zeros(n), np.zeros(rows)
        status, iters = _core.gi_solve(problem.P, problem.g, problem.M, problem.lo, problem.hi, problem.dims[1],
                                       x, z, ref_ws, first, cfg.eps_abs, cfg.max_iter)
        assert status == SOLVED and split.status == "solved"
        assert split.iterations == iters
        np.testing.assert_array_equal(split.F.ravel(), x)
        warm += not first and _core.gi_active_inequalities(ref_ws, problem.dims[1]) > 0
    assert warm >= 3  # warm starts from non-empty active sets were compared


def test_gi_solve_refuses_a_wrong_shape_naming_the_argument():
    n, rows = 3, 4
    H, g, M, lo, hi = np.eye(n), np.zeros(n), np.ones((rows, n)), np.zeros(rows), np.ones(rows)
    x, z, ws = np.zeros(n), np.zeros(rows), gi_workspace(n, rows)
    with pytest.raises(ValueError, match="^g: expected length 3, got 2"):
        _core.gi_solve(H, np.zeros(2), M, lo, hi, 0, x, z, ws, True, TOL, 10)
    with pytest.raises(ValueError, match="^M: expected n = 3 columns"):
        _core.gi_solve(H, g, np.ones((rows, 2)), lo, hi, 0, x, z, ws, True, TOL, 10)
    with pytest.raises(ValueError, match="^n_eq: expected 0 to the rows of M"):
        _core.gi_solve(H, g, M, lo, hi, 5, x, z, ws, True, TOL, 10)
    with pytest.raises(ValueError, match=r"^ws\[2\] \(rowv\): expected shape \(2, 4\)"):
        _core.gi_solve(H, g, M, lo, hi, 0, x, z, gi_workspace(n, rows + 1), True, TOL, 10)
    with pytest.raises(ValueError, match=r"^ws\[3\] \(ints\): expected a C-contiguous int64"):
        _core.gi_solve(H, g, M, lo, hi, 0, x, z, ws[:3] + (ws[3].astype(np.int32),), True, TOL, 10)
    bad = (ws[0], ws[1], ws[2], ws[3].copy())
    bad[3][WARM_ACTIVE] = n + 1
    with pytest.raises(ValueError, match=r"^ws\[3\]\[0\] \(active count\): expected 0 to n = 3"):
        _core.gi_solve(H, g, M, lo, hi, 0, x, z, bad, True, TOL, 10)
    with pytest.raises(TypeError):  # an output must be float64 and C-contiguous: never a silent copy
        _core.gi_solve(H, g, M, lo, hi, 0, np.zeros(n, np.float32), z, ws, True, TOL, 10)
