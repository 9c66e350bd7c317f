"""A compiled dense dual active-set QP solver (Goldfarb & Idnani, 1983), warm started.

It solves the load-distribution QP in the stacked form of
:class:`~coopctrl.load_distribution.problem.LoadDistributionProblem`:

.. math::

    \\min_x \\tfrac12 x^T H x + g^T x \\quad\\text{s.t.}\\quad
    M_{r} x = lo_r = hi_r \\;(r < n_{eq}), \\qquad lo_r \\le M_r x \\le hi_r \\;(r \\ge n_{eq}),

with ``H`` (n x n) symmetric positive definite, ``M = [G; C]`` (n_rows x n), and infinite bounds
allowed on either side of an inequality row. In the loop, ``x = F`` (6m or 3m contact wrenches),
the first ``n_eq`` rows are the wrench balance ``G F = w_N`` and the rest the min-grip,
friction-pyramid and torque-limit families.

**The method** (Goldfarb & Idnani, Math. Programming 27, 1983; the variant of quadprog's
``solve.QP``). Each side of a row is a constraint ``a^T x >= b`` (lower side ``a = M_r``,
``b = lo_r``; upper side ``a = -M_r``, ``b = -hi_r``). With ``H = L L^T`` and the active normals
``N`` (n x q), the solver keeps

.. math::

    J = L^{-T} Q, \\qquad Q^T L^{-1} N = \\begin{bmatrix} R \\\\ 0 \\end{bmatrix},

``Q`` orthogonal, ``R`` (q x q) upper triangular, so that ``J_2 J_2^T`` (the last n - q columns)
is the reduced inverse Hessian and ``J_1 R^{-T}`` the pseudo-inverse of the active normals. The
iterate is always *dual feasible*: ``x`` minimises the objective on the active set, with
multipliers ``u >= 0`` on the active inequalities. Each iteration takes the most violated
constraint ``p`` (violation ``s_p = a_p^T x - b_p < -tol``, scaled by ``|a_p|``) and moves along

.. math::

    d = J^T a_p, \\quad z = J_2 d_2 \\;(\\text{primal}), \\quad r = R^{-1} d_1 \\;(\\text{dual}),
    \\quad t_2 = -s_p / (z^T a_p), \\quad t_1 = \\min_{i:\\, r_i > 0} u_i / r_i ,

by ``t = min(t_1, t_2)``: ``x += t z``, ``u -= t r``, ``u_p += t``. A full step (``t = t_2``)
adds ``p`` (Givens rotations fold ``d_2`` into one entry: the new column of ``R``); a partial step
drops the blocking constraint ``i`` (Givens rotations restore the triangle) and the step for
``p`` is computed again. If ``a_p`` lies in the span of the active normals (``|d_2| <=
DEP_TOL |d|``, the test that replaces quadprog's ``|z|^2 <= eps``), there is no primal step:
with some ``r_i > 0`` the solver takes the dual step ``t_1`` and drops ``i`` -- this is how
redundant (linearly dependent) active rows are handled: never both in the active set, so ``R``
stays regular and nothing cycles -- and with none the problem is **infeasible** (a Farkas
certificate: ``a_p`` is a non-positive combination of active normals). The dual objective grows
strictly at every step with ``t > 0``, so the method terminates.

**Warm start.** In a dual method a warm start must be *dual* feasible, not primal feasible:
the solve starts from the previous solve's active set ``A`` (its inequality rows, kept in the
workspace). The equality rows and then the rows of ``A`` are added to the factorisation without
taking steps (a row dependent on those already added is skipped), ``x`` and ``u`` are computed
as the minimiser on that set,

.. math::

    v = b_A - N^T x_0, \\quad w = R^{-T} v, \\quad x = x_0 + J_1 w, \\quad u = R^{-1} w,
    \\qquad x_0 = -H^{-1} g ,

and while an inequality multiplier is negative the most negative one is dropped (one Givens
sweep) and ``x, u`` computed again. What is left is a valid start of the dual method (an
"S-pair"): when the previous active set is still the right one, no iteration is needed at all;
when it is partly wrong, the wrong rows go first and the method carries on as from a cold start
with part of the work done. A cold start (``ints[0] = 0`` in the workspace) adds only the
equalities.

Most ticks keep their active set, so a *fast path* is tried first, without ``J`` and ``R``:
with ``Y = L^{-1} N^T`` (sparse: ``L^{-1}`` is diagonal for the pseudo-inverse split, and the
rows of different arms do not overlap) it solves ``(Y^T Y) u = b_A - N^T x_0`` by a Cholesky
factorisation of the small Gram matrix, sets ``x = x_0 + L^{-T} Y u``, and returns at once with
0 iterations if the Gram matrix is well conditioned (no dependent row, see :data:`GRAM_TOL`),
``u >= 0`` on the inequalities, the active rows hold and every other row is within its bounds
(all within ``tol``) -- the KKT conditions, so ``x`` is the optimum. Otherwise the factorised
warm start above runs.

**Workspace** (allocate once with :func:`gi_workspace`, pass to every solve; nothing is allocated
per solve). A tuple ``(mats, vecs, rowv, ints)``:

- ``mats`` float64 (3, n, n): ``mats[0] = J^T`` (row i is column i of ``J``; ``Y^T`` in the fast
  path), ``mats[1] = R`` (upper triangle of the leading q x q block; the Gram matrix's Cholesky
  factor in the fast path), ``mats[2] = L^{-1}`` (the cached inverse Cholesky
  factor of ``H``, lower triangular, valid while ``ints[1] == 1``).
- ``vecs`` float64 (8, n + 1): ``d``, ``z``, ``r``, ``u`` (multipliers of the active set, entry
  ``q`` is that of the constraint being added), ``x_0``, and three scratch vectors.
- ``rowv`` float64 (2, n_rows): the Euclidean norm of each row of ``M``, and scratch.
- ``ints`` int64 (4 + 4 n + 3 n_rows): ``ints[0] = q`` (number of active constraints),
  ``ints[1]`` = 1 if ``mats[2]`` holds the factor of the current ``H``, ``ints[2]`` = 1 if the last
  solve was answered by the fast path (below), ``ints[3]`` = 1 if that ``H`` is diagonal,
  ``ints[4:4+n]`` the active codes (``2 r`` for the lower side of row ``r``, ``2 r + 1`` for its
  upper side, in the order of ``R``), ``ints[4+n:4+4n]`` scratch (the previous codes and the
  column ranges of the fast path), ``ints[4+4n:4+4n+n_rows]`` per row: 1 if the row is active,
  then per row the first and one past the last column of its non-zero entries (found in one
  scan per solve: every product with a row of ``M`` runs over that range only, which makes the
  block-sparse rows of the load distribution cheap).

The active set in ``ints`` is the warm start of the next solve; set ``ints[0] = 0`` for a cold
start and ``ints[1] = 0`` when ``H`` changes (or pass ``new_H=True``).

**Output.** ``x`` (n) and ``z`` (n_rows), the multipliers in the sign convention of proxsuite:
``H x + g + M^T z = 0``, ``z_r > 0`` at an active upper bound, ``z_r < 0`` at an active lower
bound, ``z_r = 0`` for an inactive row (equality rows: any sign). The binding rows are those with
``z_r != 0`` (or the codes ``ints[4:4+q]``). The status codes are :data:`SOLVED`,
:data:`INFEASIBLE`, :data:`MAX_ITER` and :data:`NOT_CONVEX` (``H`` not positive definite, or a
non-finite input).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: Status: optimal; ``x`` and ``z`` hold the answer.
SOLVED = 0
#: Status: the constraints are inconsistent (certified by a dependent violated row with no
#: blocking multiplier); ``x`` is the last iterate.
INFEASIBLE = 1
#: Status: ``max_iter`` iterations reached; ``x`` is the last (dual feasible, primal infeasible) iterate.
MAX_ITER = 2
#: Status: ``H`` is not positive definite (Cholesky failed), or ``g`` or ``M`` has a non-finite
#: entry, or a bound is NaN.
NOT_CONVEX = 3
#: Names of the status codes, by code.
STATUS_NAMES = ("solved", "infeasible", "max_iter", "not_convex")

#: The warm start's scalar state, ``ws[3][0:4]`` by name (the fields of ``GIWarmState`` in
#: coopctrl/core/goldfarb_idnani.h): the number of active constraints (0: cold start), 1 if ``mats[2]``
#: holds the factor of the current ``H``, 1 if the last solve took the fast path, 1 if that ``H`` is diagonal.
WARM_ACTIVE, WARM_FACTOR_VALID, WARM_FAST_PATH, WARM_H_DIAGONAL = 0, 1, 2, 3

#: Relative size ``|d_2| / |d|`` below which a constraint is taken as linearly dependent on the
#: active set (rounding of an exactly dependent row gives about 1e-16 to 1e-14).
DEP_TOL = 1e-12
#: The fast path gives up (for the factorised path) when a pivot of the Gram matrix falls below
#: this fraction of its diagonal entry: an angle of about 1e-7 between a row and the span of the
#: others, where squaring the condition number would cost accuracy.
GRAM_TOL = 1e-14


def gi_workspace(n, n_rows):
    """The workspace tuple ``(mats, vecs, rowv, ints)`` for ``n`` variables and ``n_rows`` rows of
    ``M`` (layout in the module docstring), with an empty active set (cold start). Plain numpy: the C++
    solver (``coopctrl._core.gi_solve``) and the numba kernel take the same tuple."""
    mats = np.zeros((3, n, n))
    vecs = np.zeros((8, n + 1))
    rowv = np.zeros((2, n_rows))
    ints = np.zeros(4 + 4 * n + 3 * n_rows, np.int64)
    return mats, vecs, rowv, ints


@njit(cache=True)
def _factor(H, Linv, work):
    """Cholesky ``H = L L^T`` and ``Linv = L^{-1}`` (lower triangular), written as loops.
    ``work`` (n, n) holds ``L``. Returns False if ``H`` is not positive definite."""
    n = H.shape[0]
    L = work
    for j in range(n):
        s = H[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not (s > 0.0) or not math.isfinite(s):
            return False
        ljj = math.sqrt(s)
        L[j, j] = ljj
        for i in range(j + 1, n):
            s = H[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / ljj
    for i in range(n):
        for j in range(n):
            Linv[i, j] = 0.0
    for j in range(n):
        Linv[j, j] = 1.0 / L[j, j]
        for i in range(j + 1, n):
            s = 0.0
            for k in range(j, i):
                s += L[i, k] * Linv[k, j]
            Linv[i, j] = -s / L[i, i]
    return True


@njit(cache=True)
def _add_constraint(JT, R, d, q, n):
    """Append the constraint whose ``d = J^T a`` is given to the factorisation (q -> q + 1):
    one Givens rotation of the pair (q, i) per non-zero ``d[i]``, ``i > q``, folds ``d[q:]``
    into ``d[q]`` (applied to rows q and i of ``J^T``; zero entries cost nothing, which keeps
    the sparse rows of the grasp matrix cheap), and ``d[:q+1]`` becomes column q of ``R``."""
    for i in range(q + 1, n):
        b = d[i]
        if b == 0.0:
            continue
        a = d[q]
        h = math.sqrt(a * a + b * b)
        c = a / h
        s = b / h
        d[q] = h
        d[i] = 0.0
        for j in range(n):
            t1 = JT[q, j]
            t2 = JT[i, j]
            JT[q, j] = c * t1 + s * t2
            JT[i, j] = c * t2 - s * t1
    for i in range(q + 1):
        R[i, q] = d[i]


@njit(cache=True)
def _drop_constraint(JT, R, u, act, k, q, n):
    """Remove active constraint ``k`` (0 <= k < q) from the factorisation (q -> q - 1): shift
    the columns of ``R`` (and ``act``, ``u`` with its entry ``q``) left, and restore the upper
    triangle with Givens rotations on rows (j, j+1) of ``R`` and of ``J^T``."""
    for j in range(k, q - 1):
        for i in range(j + 2):
            R[i, j] = R[i, j + 1]
        act[j] = act[j + 1]
        u[j] = u[j + 1]
    u[q - 1] = u[q]
    u[q] = 0.0
    for i in range(q):
        R[i, q - 1] = 0.0
    for j in range(k, q - 1):
        a = R[j, j]
        b = R[j + 1, j]
        if b == 0.0:
            continue
        h = math.sqrt(a * a + b * b)
        c = a / h
        s = b / h
        R[j, j] = h
        R[j + 1, j] = 0.0
        for col in range(j + 1, q - 1):
            t1 = R[j, col]
            t2 = R[j + 1, col]
            R[j, col] = c * t1 + s * t2
            R[j + 1, col] = c * t2 - s * t1
        for col in range(n):
            t1 = JT[j, col]
            t2 = JT[j + 1, col]
            JT[j, col] = c * t1 + s * t2
            JT[j + 1, col] = c * t2 - s * t1


@njit(cache=True)
def _normal_dot_J(JT, M, row, sign, d, n, c0, c1):
    """``d = J^T a`` for ``a = sign * M[row]`` (non-zero in columns ``c0:c1``); returns ``|d|^2``."""
    tot = 0.0
    for i in range(n):
        s = 0.0
        for j in range(c0, c1):
            s += JT[i, j] * M[row, j]
        s *= sign
        d[i] = s
        tot += s * s
    return tot


@njit(cache=True)
def _tail_norm2(d, q, n):
    s = 0.0
    for i in range(q, n):
        s += d[i] * d[i]
    return s


@njit(cache=True)
def _equality_point(JT, R, M, lo, hi, act, q, n, x0, x, u, v, rfirst, rend):
    """``x, u`` of the minimiser on the active set: ``v = b_A - N^T x_0``, ``w = R^{-T} v``,
    ``x = x_0 + J_1 w``, ``u = R^{-1} w``."""
    for i in range(q):
        code = act[i]
        row = code >> 1
        s = 0.0
        for j in range(rfirst[row], rend[row]):
            s += M[row, j] * x0[j]
        if code & 1:
            v[i] = s - hi[row]  # b = -hi, a = -M_r: b - a^T x0 = -hi + M_r x0
        else:
            v[i] = lo[row] - s
    # forward substitution with R^T (lower): w_i = (v_i - sum_{k<i} R[k, i] w_k) / R[i, i]
    for i in range(q):
        s = v[i]
        for k in range(i):
            s -= R[k, i] * v[k]
        v[i] = s / R[i, i]
    for j in range(n):
        x[j] = x0[j]
    for i in range(q):
        w = v[i]
        for j in range(n):
            x[j] += JT[i, j] * w
    # back substitution u = R^{-1} w
    for i in range(q - 1, -1, -1):
        s = v[i]
        for k in range(i + 1, q):
            s -= R[i, k] * u[k]
        u[i] = s / R[i, i]
    u[q] = 0.0


@njit(cache=True)
def _try_active_set(Linv, is_diag, M, lo, hi, n_eq, prev, n_prev, x0, x, z, u, v, t, Y, S, rownorm, mark, act,
                    sup_lo, sup_hi, rfirst, rend, tol):
    """The fast path: is the minimiser on (equalities + the previous active set) the optimum?

    Solves ``(Y^T Y) u = b_A - N^T x_0`` with ``Y = L^{-1} N^T`` (rows of ``Y`` stored in ``Y``,
    their non-zero column ranges in ``sup_lo``/``sup_hi``; the Gram matrix and its Cholesky
    factor in ``S``), ``x = x_0 + L^{-T} Y u``. Returns the number of active constraints ``q``
    (with ``act``, ``x``, ``z`` written) if the Gram matrix is regular, the inequality
    multipliers are >= 0 and every other row holds within ``tol``; otherwise -1 (``x``, ``z``,
    ``act`` and ``mark`` are then to be rewritten by the caller)."""
    n_rows, n = M.shape
    q = 0
    for k in range(n_eq + n_prev):
        if k < n_eq:
            code = 2 * k
        else:
            code = prev[k - n_eq]
        row = code >> 1
        if k >= n_eq:
            if row < n_eq or row >= n_rows or mark[row] != 0:
                continue
            if not math.isfinite(hi[row] if code & 1 else lo[row]):
                continue
        if q == n:
            return -1
        sign = -1.0 if code & 1 else 1.0
        # y = sign L^{-1} M[row] and its non-zero column range
        first = rfirst[row]
        last = rend[row] - 1
        if last < first:
            return -1
        if is_diag:
            for j in range(first, last + 1):
                Y[q, j] = sign * M[row, j] * Linv[j, j]
            sup_hi[q] = last + 1
        else:
            for i in range(n):
                acc = 0.0
                for j in range(first, i + 1):
                    acc += Linv[i, j] * M[row, j]
                Y[q, i] = sign * acc
            sup_hi[q] = n
        sup_lo[q] = first
        act[q] = code
        mark[row] = 1
        q += 1
    # Gram matrix S = Y Y^T (lower triangle) over overlapping column ranges, Cholesky in place
    for i in range(q):
        for j in range(i + 1):
            a = max(sup_lo[i], sup_lo[j])
            b = min(sup_hi[i], sup_hi[j])
            acc = 0.0
            for c in range(a, b):
                acc += Y[i, c] * Y[j, c]
            S[i, j] = acc
    for j in range(q):
        diag = S[j, j]
        acc = diag
        for c in range(j):
            acc -= S[j, c] * S[j, c]
        if not (acc > GRAM_TOL * diag):
            # a dependent or nearly dependent row: the Gram matrix squares the condition
            # number, so the factorised path (orthogonal transformations) takes it
            return -1
        ljj = math.sqrt(acc)
        S[j, j] = ljj
        for i in range(j + 1, q):
            acc = S[i, j]
            for c in range(j):
                acc -= S[i, c] * S[j, c]
            S[i, j] = acc / ljj
    # right-hand side v = b_A - N^T x0 and u = S^{-1} v
    for i in range(q):
        code = act[i]
        row = code >> 1
        acc = 0.0
        for j in range(rfirst[row], rend[row]):
            acc += M[row, j] * x0[j]
        if code & 1:
            v[i] = acc - hi[row]
        else:
            v[i] = lo[row] - acc
    for i in range(q):
        acc = v[i]
        for c in range(i):
            acc -= S[i, c] * v[c]
        v[i] = acc / S[i, i]
    for i in range(q - 1, -1, -1):
        acc = v[i]
        for c in range(i + 1, q):
            acc -= S[c, i] * u[c]
        u[i] = acc / S[i, i]
        if i >= n_eq and u[i] < 0.0:
            return -1
    # x = x0 + L^{-T} (Y^T u)
    for j in range(n):
        t[j] = 0.0
    for i in range(q):
        ui = u[i]
        for j in range(sup_lo[i], sup_hi[i]):
            t[j] += ui * Y[i, j]
    if is_diag:
        for j in range(n):
            x[j] = x0[j] + Linv[j, j] * t[j]
    else:
        for j in range(n):
            acc = 0.0
            for i in range(j, n):
                acc += Linv[i, j] * t[i]
            x[j] = x0[j] + acc
    # the active rows hold (the Gram solve was accurate) and every other row is within bounds?
    for i in range(q):
        code = act[i]
        row = code >> 1
        acc = 0.0
        for j in range(rfirst[row], rend[row]):
            acc += M[row, j] * x[j]
        b = hi[row] if code & 1 else lo[row]
        if abs(acc - b) > tol * rownorm[row]:
            return -1
    for row in range(n_eq, n_rows):
        if mark[row] != 0 or rownorm[row] == 0.0:
            continue
        acc = 0.0
        for j in range(rfirst[row], rend[row]):
            acc += M[row, j] * x[j]
        if lo[row] - acc > tol * rownorm[row] or acc - hi[row] > tol * rownorm[row]:
            return -1
    for i in range(q):
        code = act[i]
        if code & 1:
            z[code >> 1] = u[i]
        else:
            z[code >> 1] = -u[i]
    return q


@njit(cache=True)
def gi_solve(H, g, M, lo, hi, n_eq, x, z, ws, new_H, tol, max_iter):
    """Solve ``min 1/2 x^T H x + g^T x`` s.t. ``M[:n_eq] x = lo[:n_eq]`` and
    ``lo <= M x <= hi`` (rows ``n_eq:``), warm started from the active set in ``ws``.

    Args:
        H: (n, n) symmetric positive definite Hessian (only read when it is factorised).
        g: (n,) linear term.
        M: (n_rows, n) constraint rows; the first ``n_eq`` are equalities.
        lo, hi: (n_rows,) bounds (``lo[r] = hi[r]`` on equality rows; +-inf allowed on inequalities).
        n_eq: Number of equality rows.
        x: (n,) output, the primal answer.
        z: (n_rows,) output, the multipliers (``H x + g + M^T z = 0``; > 0 at an upper bound).
        ws: The workspace of :func:`gi_workspace` (holds the factor of ``H`` and the active set).
        new_H: True if ``H`` changed since the last solve with this workspace (refactorise).
        tol: Primal feasibility tolerance: a side of a row is violated when its violation divided
            by the row's norm exceeds ``tol`` [units of x, e.g. N].
        max_iter: Iteration limit (additions and drops of constraints).

    Returns:
        ``(status, iterations)``: a status code (:data:`SOLVED`, :data:`INFEASIBLE`,
        :data:`MAX_ITER`, :data:`NOT_CONVEX`) and the number of additions and drops after the
        warm start (0 when the previous active set was still the answer's).
    """
    mats, vecs, rowv, ints = ws
    n = H.shape[0]
    n_rows = M.shape[0]
    JT = mats[0]
    R = mats[1]
    Linv = mats[2]
    d = vecs[0]
    zz = vecs[1]
    r = vecs[2]
    u = vecs[3]
    x0 = vecs[4]
    v = vecs[5]
    rownorm = rowv[0]
    act = ints[4:4 + n]
    prev = ints[4 + n:4 + 2 * n]
    mark = ints[4 + 4 * n:4 + 4 * n + n_rows]
    rfirst = ints[4 + 4 * n + n_rows:4 + 4 * n + 2 * n_rows]
    rend = ints[4 + 4 * n + 2 * n_rows:4 + 4 * n + 3 * n_rows]
    for i in range(n_rows):
        z[i] = 0.0
    # ---- factor of H (cached) and the unconstrained minimiser x0 = -H^{-1} g
    if new_H or ints[1] == 0:
        ints[1] = 0
        if not _factor(H, Linv, JT):
            ints[0] = 0
            for j in range(n):
                x[j] = 0.0
            return NOT_CONVEX, 0
        ints[1] = 1
        diag = 1
        for i in range(n):
            for j in range(i):
                if Linv[i, j] != 0.0:
                    diag = 0
        ints[3] = diag
    for i in range(n):  # v = L^{-1} g
        s = 0.0
        for j in range(i + 1):
            s += Linv[i, j] * g[j]
        v[i] = s
    for j in range(n):  # x0 = -L^{-T} v
        s = 0.0
        for i in range(j, n):
            s += Linv[i, j] * v[i]
        x0[j] = -s
        if not math.isfinite(x0[j]):
            ints[0] = 0
            return NOT_CONVEX, 0
    for i in range(n_rows):
        c0 = 0
        while c0 < n and M[i, c0] == 0.0:
            c0 += 1
        c1 = n
        while c1 > c0 and M[i, c1 - 1] == 0.0:
            c1 -= 1
        rfirst[i] = c0
        rend[i] = c1
        s = 0.0
        for j in range(c0, c1):
            s += M[i, j] * M[i, j]
        rownorm[i] = math.sqrt(s)
        mark[i] = 0
        if not math.isfinite(s) or math.isnan(lo[i]) or math.isnan(hi[i]):
            ints[0] = 0
            return NOT_CONVEX, 0
        if s == 0.0 and (lo[i] > tol or hi[i] < -tol):
            # a zero row with a bound it cannot meet (e.g. a joint the contact cannot load
            # whose bias exceeds its limit): inconsistent whatever x is
            ints[0] = 0
            for j in range(n):
                x[j] = x0[j]
            return INFEASIBLE, 0
    # ---- fast path: the equalities and the previous active set may still be optimal
    n_prev = ints[0]
    for i in range(n_prev):
        prev[i] = act[i]
    q = _try_active_set(Linv, ints[3] == 1, M, lo, hi, n_eq, prev, n_prev, x0, x, z, u, v, vecs[6], JT, R,
                        rownorm, mark, act, ints[4 + 2 * n:4 + 3 * n], ints[4 + 3 * n:4 + 4 * n], rfirst, rend,
                        tol)
    if q >= 0:
        ints[0] = q
        ints[2] = 1
        return SOLVED, 0
    ints[2] = 0
    for i in range(n_rows):
        mark[i] = 0
    # ---- warm start: equalities, then the previous active inequalities, added without steps
    for i in range(n):
        for j in range(n):
            JT[i, j] = Linv[i, j]
    q = 0
    skipped_eq = False
    for row in range(n_eq):
        if q == n:
            skipped_eq = True
            break
        tot = _normal_dot_J(JT, M, row, 1.0, d, n, rfirst[row], rend[row])
        if _tail_norm2(d, q, n) <= DEP_TOL * DEP_TOL * tot:
            skipped_eq = True
            continue
        _add_constraint(JT, R, d, q, n)
        act[q] = 2 * row
        mark[row] = 1
        q += 1
    for i in range(n_prev):
        code = prev[i]
        row = code >> 1
        if row < n_eq or row >= n_rows or mark[row] != 0 or q == n:
            continue
        if code & 1:
            if not math.isfinite(hi[row]):
                continue
            sign = -1.0
        else:
            if not math.isfinite(lo[row]):
                continue
            sign = 1.0
        tot = _normal_dot_J(JT, M, row, sign, d, n, rfirst[row], rend[row])
        if _tail_norm2(d, q, n) <= DEP_TOL * DEP_TOL * tot:
            continue
        _add_constraint(JT, R, d, q, n)
        act[q] = code
        mark[row] = 1
        q += 1
    _equality_point(JT, R, M, lo, hi, act, q, n, x0, x, u, v, rfirst, rend)
    iters = 0
    # drop warm rows with negative multipliers (most negative first) until dual feasible
    while True:
        kmin = -1
        umin = 0.0
        for i in range(q):
            if (act[i] >> 1) >= n_eq and u[i] < umin:
                umin = u[i]
                kmin = i
        if kmin < 0:
            break
        mark[act[kmin] >> 1] = 0
        _drop_constraint(JT, R, u, act, kmin, q, n)
        q -= 1
        iters += 1
        _equality_point(JT, R, M, lo, hi, act, q, n, x0, x, u, v, rfirst, rend)
    if skipped_eq:
        # a dependent equality row must hold at the minimiser of the independent ones
        for row in range(n_eq):
            if mark[row] == 0:
                s = 0.0
                for j in range(rfirst[row], rend[row]):
                    s += M[row, j] * x[j]
                if abs(s - lo[row]) > tol * max(rownorm[row], 1e-300):
                    ints[0] = q
                    return INFEASIBLE, iters
    # ---- the dual active-set iterations
    status = SOLVED
    while True:
        # most violated side of an inactive inequality row (violation / |row|)
        p = -1
        worst = tol
        for row in range(n_eq, n_rows):
            if mark[row] != 0 or rownorm[row] == 0.0:
                continue
            s = 0.0
            for j in range(rfirst[row], rend[row]):
                s += M[row, j] * x[j]
            viol = lo[row] - s
            if viol > worst * rownorm[row]:
                worst = viol / rownorm[row]
                p = 2 * row
            viol = s - hi[row]
            if viol > worst * rownorm[row]:
                worst = viol / rownorm[row]
                p = 2 * row + 1
        if p < 0:
            break
        prow = p >> 1
        sign = -1.0 if (p & 1) else 1.0
        bp = -hi[prow] if (p & 1) else lo[prow]
        u[q] = 0.0
        # step for constraint p: repeated after each drop
        while True:
            if iters >= max_iter:
                status = MAX_ITER
                break
            iters += 1
            s = 0.0
            for j in range(rfirst[prow], rend[prow]):
                s += M[prow, j] * x[j]
            sp = sign * s - bp  # < 0 while violated
            tot = _normal_dot_J(JT, M, prow, sign, d, n, rfirst[prow], rend[prow])
            tail = _tail_norm2(d, q, n)
            # r = R^{-1} d_1 and the blocking multiplier t1
            t1 = np.inf
            it1 = -1
            for i in range(q - 1, -1, -1):
                acc = d[i]
                for k in range(i + 1, q):
                    acc -= R[i, k] * r[k]
                acc /= R[i, i]
                r[i] = acc
            for i in range(q):
                if (act[i] >> 1) >= n_eq and r[i] > 0.0:
                    t = u[i] / r[i]
                    if t < t1:
                        t1 = t
                        it1 = i
            if tail <= DEP_TOL * DEP_TOL * tot or q == n:
                # no primal step: a_p is in the span of the active normals
                if it1 < 0:
                    status = INFEASIBLE
                    break
                for i in range(q):
                    u[i] -= t1 * r[i]
                u[q] += t1
                mark[act[it1] >> 1] = 0
                _drop_constraint(JT, R, u, act, it1, q, n)
                q -= 1
                continue
            # primal direction zz = J_2 d_2; full step t2
            for j in range(n):
                zz[j] = 0.0
            for i in range(q, n):
                di = d[i]
                if di != 0.0:
                    for j in range(n):
                        zz[j] += JT[i, j] * di
            t2 = -sp / tail  # z^T a_p = |d_2|^2
            if t2 <= t1:
                t = t2
            else:
                t = t1
            for j in range(n):
                x[j] += t * zz[j]
            for i in range(q):
                u[i] -= t * r[i]
            u[q] += t
            if t2 <= t1:
                _add_constraint(JT, R, d, q, n)
                act[q] = p
                mark[prow] = 1
                q += 1
                break
            mark[act[it1] >> 1] = 0
            _drop_constraint(JT, R, u, act, it1, q, n)
            q -= 1
        if status != SOLVED:
            break
    ints[0] = q
    # multipliers per row, in proxsuite's convention
    for i in range(q):
        code = act[i]
        row = code >> 1
        if code & 1:
            z[row] = u[i]
        else:
            z[row] = -u[i]
    return status, iters


@njit(cache=True)
def gi_active_inequalities(ws, n_eq):
    """Number of inequality rows in the active set that the last :func:`gi_solve` with workspace
    ``ws`` left (rows ``>= n_eq`` held at one of their bounds; the equality rows are not counted).
    Reads ``ints[0] = q`` and the codes ``ints[4:4+q]`` (module docstring); allocates nothing."""
    ints = ws[3]
    count = 0
    for i in range(ints[0]):
        if (ints[4 + i] >> 1) >= n_eq:
            count += 1
    return count
