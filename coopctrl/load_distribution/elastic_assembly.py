"""The elastic split's QP inputs, filled in place by a numba function (the compiled tick's form of
:meth:`LoadDistributionProblem.update <coopctrl.load_distribution.problem.LoadDistributionProblem.update>`
with ``split = "elastic"``).

With the grasp stiffness in the world frame (:meth:`GraspCompliance.stiffness_world
<coopctrl.controllers.GraspCompliance.stiffness_world>`)

.. math::
    K = \\mathrm{blockdiag}_i\\big(\\mathrm{sym}(R_b K_i R_b^T)\\big), \\qquad
    R_b = \\mathrm{blockdiag}(R_0, R_0) \\text{ (spatial)}, \\quad
    \\begin{pmatrix} c & -s & 0 \\\\ s & c & 0 \\\\ 0 & 0 & 1 \\end{pmatrix} \\text{ (planar)},

``R_0`` the nominal object rotation, ``K_i`` the object-frame grasp stiffness and
``sym(X) = (X + X^T) / 2``, the external part is ``A_K w_N = K G^T (G K G^T)^{-1} w_N`` and the
cost's Hessian ``P = sym(K^{-1})`` (block by block: ``K`` is block diagonal).

The Python problem takes any ``K`` (n x n) and computes these two with numpy: the one QP input that is
still written twice (its rows are those of :mod:`.assembly`).
"""

from __future__ import annotations

import math

from numba import njit

from plants.cooperative._linalg import cholesky_solve_n
from plants.frames import rotation_zyx_into


@njit(cache=True)
def _invert_block(K, P, o, p, work):
    """``P[o:o+p, o:o+p] = K[o:o+p, o:o+p]^{-1}`` by Gauss-Jordan with partial pivoting; ``work`` (p, 2p)
    scratch. Returns False if the block is singular."""
    for r in range(p):
        for c in range(p):
            work[r, c] = K[o + r, o + c]
            work[r, p + c] = 1.0 if r == c else 0.0
    for c in range(p):
        piv = c
        big = abs(work[c, c])
        for r in range(c + 1, p):
            if abs(work[r, c]) > big:
                big = abs(work[r, c])
                piv = r
        if not big > 0.0:
            return False
        if piv != c:
            for j in range(2 * p):
                t = work[c, j]
                work[c, j] = work[piv, j]
                work[piv, j] = t
        d = work[c, c]
        for j in range(2 * p):
            work[c, j] /= d
        for r in range(p):
            if r != c:
                f = work[r, c]
                if f != 0.0:
                    for j in range(2 * p):
                        work[r, j] -= f * work[c, j]
    for r in range(p):
        for c in range(p):
            P[o + r, o + c] = work[r, p + c]
    return True


@njit(cache=True)
def fill_elastic_split(M, k, K_obj, Y0, spatial, K, P, w, external, KGt, A, y, Rb, work):
    """Fill ``K`` (n, n), ``P`` (n, n) and ``external`` (n) of the elastic split at the nominal object
    pose ``Y0``; ``G = M[:k]`` and ``w`` (k) the load. ``K_obj`` (m, p, p) the object-frame grasp
    stiffnesses; ``KGt`` (n, k), ``A`` (k, k), ``y`` (k), ``Rb`` (p, p), ``work`` (p, 2p) scratch.

    Returns ``(code, P_changed)``: ``code`` 0, or -3 when a block of ``K`` is singular, -1 when
    ``G K G^T`` is not positive definite; ``P`` is recomputed (and ``P_changed`` True) only when
    ``K`` changed since the last call with these arrays (``K`` and ``P`` hold the previous values).
    """
    m = K_obj.shape[0]
    p = K_obj.shape[1]
    n = m * p
    for r in range(p):
        for c in range(p):
            Rb[r, c] = 0.0
    if spatial:
        R0 = Rb[:3, :3]
        rotation_zyx_into(Y0[3:6], R0)
        for r in range(3):
            for c in range(3):
                Rb[3 + r, 3 + c] = Rb[r, c]
    else:
        cs, sn = math.cos(Y0[2]), math.sin(Y0[2])
        Rb[0, 0], Rb[0, 1], Rb[1, 0], Rb[1, 1], Rb[2, 2] = cs, -sn, sn, cs, 1.0
    changed = False
    for i in range(m):
        o = i * p
        # Ki = Rb K_obj Rb^T into work[:, :p] (via work[:, p:] = K_obj Rb^T)
        for r in range(p):
            for c in range(p):
                s = 0.0
                for b in range(p):
                    s += K_obj[i, r, b] * Rb[c, b]
                work[r, p + c] = s
        for r in range(p):
            for c in range(p):
                s = 0.0
                for b in range(p):
                    s += Rb[r, b] * work[b, p + c]
                work[r, c] = s
        for r in range(p):
            for c in range(p):
                v = 0.5 * (work[r, c] + work[c, r])
                if v != K[o + r, o + c]:
                    changed = True
        for r in range(p):
            for c in range(r, p):
                v = 0.5 * (work[r, c] + work[c, r])
                K[o + r, o + c] = v
                K[o + c, o + r] = v
    if changed:
        for r in range(n):
            for c in range(n):
                P[r, c] = 0.0
        for i in range(m):
            if not _invert_block(K, P, i * p, p, work):
                return -3, changed
        for r in range(n):
            for c in range(r + 1, n):
                v = 0.5 * (P[r, c] + P[c, r])
                P[r, c] = v
                P[c, r] = v
    # KGt = K G^T (K block diagonal), A = G K G^T
    for i in range(m):
        o = i * p
        for a in range(p):
            for r in range(k):
                s = 0.0
                for b in range(p):
                    s += K[o + a, o + b] * M[r, o + b]
                KGt[o + a, r] = s
    for a in range(k):
        for b in range(k):
            s = 0.0
            for c in range(n):
                s += M[a, c] * KGt[c, b]
            A[a, b] = s
    for a in range(k):
        for b in range(a + 1, k):
            v = 0.5 * (A[a, b] + A[b, a])
            A[a, b] = v
            A[b, a] = v
    if not cholesky_solve_n(A, w, y, k):  # A = L L^T (lower triangle), then A y = w
        return -1, changed
    for c in range(n):
        s = 0.0
        for a in range(k):
            s += KGt[c, a] * y[a]
        external[c] = s
    return 0, changed
