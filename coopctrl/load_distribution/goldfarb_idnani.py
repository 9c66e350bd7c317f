"""The compiled dense dual active-set QP solver (Goldfarb & Idnani, 1983), warm started: its method, its
workspace and its codes. The solver is the C++ core's (``coopctrl._core.gi_solve``, coopctrl/core/goldfarb_idnani.h).

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

import numpy as np

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
    ``M`` (layout in the module docstring), with an empty active set (cold start), for the C++ solver
    (``coopctrl._core.gi_solve``)."""
    mats = np.zeros((3, n, n))
    vecs = np.zeros((8, n + 1))
    rowv = np.zeros((2, n_rows))
    ints = np.zeros(4 + 4 * n + 3 * n_rows, np.int64)
    return mats, vecs, rowv, ints


def gi_cold_start(ws) -> None:
    """Empty the active set of the workspace ``ws`` (:func:`gi_workspace`): its next solve starts cold."""
    ws[3][WARM_ACTIVE] = 0
