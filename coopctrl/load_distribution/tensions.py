"""Pair tensions of an internal load on the virtual-linkage columns, compiled: the one definition the compiled
tick's squeeze (:func:`coopctrl.loop.squeeze.pair_squeeze_into`) and the public
:func:`~coopctrl.load_distribution.grasp_matrix.pair_tensions` run (docs/model.md section 6).

For pair columns ``E`` (R, P) (the force rows of the squeeze basis of
:func:`coopctrl.load_distribution.assembly.fill_squeeze_basis`, or any columns) and forces ``f`` (R,) [N], the
tensions [N] nearest the desired squeeze ``s_des`` (P,) [N]:

.. math::

    s = s_{des} + E^+ (f - E s_{des})
      = s_{des} + \\sum_{j\\ \\mathrm{kept}} v_j \\left( \\frac{w_j^T f}{\\sigma_j^2} - v_j^T s_{des} \\right),
    \\qquad E V = W = [w_1 \\cdots], \\; \\lVert w_j \\rVert = \\sigma_j ,

with ``V`` the rotations of a one-sided Jacobi singular value decomposition of ``E``: ``W = E V`` has
orthogonal columns of norms ``sigma_j``, the singular values of ``E``. When ``P > R`` the rotations act on
``E^T`` instead (``E^T V = W``, ``E = V W^T``): ``s = s_des + sum_j w_j (v_j^T f - w_j^T s_des) / sigma_j^2``.
A one-sided Jacobi decomposition finds the singular values to within rounding of ``||E||`` (a structural
dependence of the pairs gives ``sigma ~ 1e-16 sigma_max``), so the rank rules apply:
``sigma / sigma_max <= PAIR_ZERO_RTOL`` is dropped, ``> PAIR_KEEP_RTOL`` kept, in between the tensions are
NaN (ill-conditioned).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from coopctrl.load_distribution.grasp_matrix import PAIR_KEEP_RTOL, PAIR_ZERO_RTOL

#: Sweeps of the one-sided Jacobi rotations at most (it converges quadratically: 3 to 8 sweeps).
MAX_SWEEPS = 60
#: Columns rotated while ``|w_i . w_j| > JACOBI_TOL * rows * |w_i| |w_j|`` (the LAPACK dgesvj rule,
#: ``eps`` times the column length).
JACOBI_TOL = 2.220446049250313e-16
#: Columns of norm below this fraction of ``||E||_F`` are not rotated: they are far below
#: ``PAIR_ZERO_RTOL * sigma_max`` (``sigma_max >= ||E||_F / sqrt(P)``), zero singular values whatever
#: their direction.
NEGLIGIBLE = 1e-14


def tension_work(R: int, P: int):
    """Scratch ``(W, V, sigma)`` of :func:`pair_tensions_into` for ``R`` force rows and ``P`` pairs."""
    rows, cols = (R, P) if P <= R else (P, R)
    return np.zeros((rows, cols)), np.zeros((cols, cols)), np.zeros(cols)


@njit(cache=True)
def pair_tensions_into(E, F, npos, desired, W, V, sigma, out):
    """The tensions ``s`` (P,) [N] of the forces ``f`` on the pair columns ``E`` (R, P) into ``out`` (module
    docstring): ``f_c = F[c // npos, c % npos]`` (``F`` (R / npos, >= npos): the force entries of the contact
    wrenches, or ``npos = 1`` and ``F`` (R, 1) a stacked load); ``desired`` (P,) ``s_des`` [N]; ``W``, ``V``,
    ``sigma`` scratch of :func:`tension_work` (``E`` is read, not changed). NaN where the columns are
    ill-conditioned. Allocates nothing."""
    R = E.shape[0]
    P = E.shape[1]
    m = R // npos
    transposed = P > R
    nr, nc = W.shape[0], W.shape[1]
    fro = 0.0
    for c in range(R):
        for e in range(P):
            v = E[c, e]
            fro += v * v
            if transposed:
                W[e, c] = v
            else:
                W[c, e] = v
    for i in range(nc):
        for j in range(nc):
            V[i, j] = 1.0 if i == j else 0.0
    small = NEGLIGIBLE * NEGLIGIBLE * fro
    tol = JACOBI_TOL * nr
    for _ in range(MAX_SWEEPS):
        rotated = False
        for i in range(nc - 1):
            for j in range(i + 1, nc):
                al = 0.0
                be = 0.0
                ga = 0.0
                for c in range(nr):
                    wi, wj = W[c, i], W[c, j]
                    al += wi * wi
                    be += wj * wj
                    ga += wi * wj
                if al <= small or be <= small or abs(ga) <= tol * math.sqrt(al * be):
                    continue
                rotated = True
                zeta = (be - al) / (2.0 * ga)
                t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / math.sqrt(1.0 + t * t)
                sn = cs * t
                for c in range(nr):
                    wi, wj = W[c, i], W[c, j]
                    W[c, i] = cs * wi - sn * wj
                    W[c, j] = sn * wi + cs * wj
                for c in range(nc):
                    vi, vj = V[c, i], V[c, j]
                    V[c, i] = cs * vi - sn * vj
                    V[c, j] = sn * vi + cs * vj
        if not rotated:
            break
    smax = 0.0
    for j in range(nc):
        s = 0.0
        for c in range(nr):
            s += W[c, j] * W[c, j]
        sigma[j] = math.sqrt(s)
        if sigma[j] > smax:
            smax = sigma[j]
    ill = not smax > 0.0
    for j in range(nc):
        rel = sigma[j] / smax if smax > 0.0 else 0.0
        if rel > PAIR_ZERO_RTOL and not rel > PAIR_KEEP_RTOL:
            ill = True
    if ill:
        for e in range(P):
            out[e] = np.nan
        return
    for e in range(P):
        out[e] = desired[e]
    for j in range(nc):
        if not sigma[j] / smax > PAIR_KEEP_RTOL:
            continue
        s2 = sigma[j] * sigma[j]
        if transposed:  # E = V W^T: s += w_j (v_j . f - w_j . s_des) / sigma_j^2
            vf = 0.0
            for i in range(m):
                for a in range(npos):
                    vf += V[npos * i + a, j] * F[i, a]
            ws = 0.0
            for e in range(P):
                ws += W[e, j] * desired[e]
            coef = (vf - ws) / s2
            for e in range(P):
                out[e] += W[e, j] * coef
        else:  # E V = W: s += v_j (w_j . f / sigma_j^2 - v_j . s_des)
            wf = 0.0
            for i in range(m):
                for a in range(npos):
                    wf += W[npos * i + a, j] * F[i, a]
            vs = 0.0
            for e in range(P):
                vs += V[e, j] * desired[e]
            coef = wf / s2 - vs
            for e in range(P):
                out[e] += V[e, j] * coef



@njit(cache=True)
def pair_tensions_batch(E, F, desired, out):
    """:func:`pair_tensions_into` of each sample ``s``: pair columns ``E[s]`` (R, P), forces ``F[s]`` (R, 1)
    [N] into ``out[s]`` (P,); NaN where ``E[s]`` or ``F[s]`` is not finite. Allocates its scratch once."""
    N, R, P = E.shape[0], E.shape[1], E.shape[2]
    rows, cols = (R, P) if P <= R else (P, R)
    W = np.zeros((rows, cols))
    V = np.zeros((cols, cols))
    sigma = np.zeros(cols)
    for s in range(N):
        ok = True
        for c in range(R):
            if not math.isfinite(F[s, c, 0]):
                ok = False
            for e in range(P):
                if not math.isfinite(E[s, c, e]):
                    ok = False
        if not ok:
            for e in range(P):
                out[s, e] = np.nan
            continue
        pair_tensions_into(E[s], F[s], 1, desired, W, V, sigma, out[s])
