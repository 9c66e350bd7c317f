"""The virtual-linkage squeeze of one tick, compiled: the kernel (:func:`coopctrl.loop.kernel.run_ticks`)
records it per tick, so a run's squeeze needs no post-processing.

The squeeze of the contact wrenches ``F`` (m, p) at the contacts ``r`` (m, npos) [m] is the pair
tensions of their internal part on the virtual-linkage columns ``E`` (the squeeze basis of
:func:`coopctrl.load_distribution.assembly.fill_squeeze_basis`, docs/model.md section 6):

.. math::

    s = s_{des} + E^+ (f_{int} - E s_{des}), \\qquad f_{int} = F - G^+ G F .

Because ``G E = 0``, ``E^+ G^+ G = 0`` (``E^+`` maps through ``range(E)``, which is orthogonal to
``range(G^T)``): ``E^+ f_int = E^+ F``, so neither ``G`` nor the object point enters and

.. math::

    s = s_{des} + \\sum_{j\\ \\mathrm{kept}} v_j \\left( \\frac{w_j^T f}{\\sigma_j^2} - v_j^T s_{des} \\right),
    \\qquad E V = W = [w_1 \\cdots], \\; \\lVert w_j \\rVert = \\sigma_j ,

with ``f`` the force entries of ``F`` (the moment rows of ``E`` are zero) and ``V`` the rotations of a
one-sided Jacobi singular value decomposition of ``E`` (its force rows, ``R = m npos`` by
``P = m(m-1)/2``): ``W = E V`` has orthogonal columns of norms ``sigma_j``, the singular values of
``E``. When ``P > R`` (six or more planar arms) the rotations act on ``E^T`` instead
(``E^T V = W``, ``E = V W^T``): ``s = s_des + sum_j w_j (v_j^T f - w_j^T s_des) / sigma_j^2``.
A one-sided Jacobi decomposition finds the singular values to within rounding of ``||E||``
(a structural dependence of the pairs gives ``sigma ~ 1e-16 sigma_max``), so the rank rules of
:func:`coopctrl.load_distribution.grasp_matrix.pair_tensions` apply unchanged:
``sigma / sigma_max <= PAIR_ZERO_RTOL`` is dropped, ``> PAIR_KEEP_RTOL`` kept, in between the tick's
squeeze is NaN (ill-conditioned), as it is where ``F`` or ``r`` is not finite or two contacts coincide.

Per tick this is small fixed-size arithmetic on the work arrays of :func:`squeeze_workspace`, made
once per run: for two contacts one column (no rotation), for three a few rotations of three columns.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from coopctrl.load_distribution.assembly import fill_squeeze_basis
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

#: The squeeze's per-run arrays: ``desired`` (P,) the desired squeeze per pair [N]; ``E`` (R, P) the
#: pair columns' force rows; ``W`` (R, P), or (P, R) when ``P > R``, the rotated columns; ``V`` the
#: rotations (square, ``W``'s columns); ``sigma`` the singular values [-].
SqueezeWork = namedtuple("SqueezeWork", "desired E W V sigma")


def squeeze_workspace(m: int, npos: int, desired) -> SqueezeWork:
    """The arrays of :func:`pair_squeeze_into` for ``m`` contacts of ``npos`` coordinates and the desired
    squeeze ``desired`` (m(m-1)/2,) [N] (made once per run; the tick allocates nothing)."""
    P = m * (m - 1) // 2
    R = m * npos
    s_des = np.array(desired, dtype=float).reshape(-1)
    if s_des.shape != (P,):
        raise ValueError(f"desired: shape {s_des.shape}; expected ({P},), one squeeze per pair of {m} contacts [N]")
    rows, cols = (R, P) if P <= R else (P, R)
    return SqueezeWork(desired=s_des, E=np.zeros((R, P)), W=np.zeros((rows, cols)), V=np.zeros((cols, cols)),
                       sigma=np.zeros(cols))


@njit(cache=True, _nrt=False)
def pair_squeeze_into(r, F, desired, E, W, V, sigma, out):
    """The squeeze ``s`` (P,) [N] of the wrenches ``F`` (m, p) at the contacts ``r`` (m, npos) [m] into
    ``out`` (see the module docstring); ``desired``, ``E``, ``W``, ``V``, ``sigma``: a :class:`SqueezeWork`.
    NaN where ``F`` or ``r`` is not finite, two contacts coincide or the pairs are ill-conditioned."""
    P = out.shape[0]
    if P == 0:
        return
    m, npos = r.shape[0], r.shape[1]
    R = m * npos
    ok = True
    for i in range(m):
        for a in range(npos):
            if not math.isfinite(r[i, a]):
                ok = False
        for a in range(F.shape[1]):
            if not math.isfinite(F[i, a]):
                ok = False
    if ok:
        for c in range(R):
            for e in range(P):
                E[c, e] = 0.0
        ok = fill_squeeze_basis(E, r, npos)
    if not ok:
        for e in range(P):
            out[e] = np.nan
        return
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


def squeeze_series(F, r_contacts, desired=None) -> np.ndarray:
    """Squeeze [N] per sample and contact pair of the contact wrenches ``F`` (N, m, p) [N, N m] at the
    contacts ``r_contacts`` (N, m, npos) [m], relative to ``desired`` (P,) [N] (zeros if None): the
    tick's :func:`pair_squeeze_into` on each sample (a run records it per tick; this serves recorded or
    made-up wrenches). NaN at the samples whose decomposition is ill-conditioned or not finite."""
    F = np.ascontiguousarray(F, dtype=float)
    r = np.ascontiguousarray(r_contacts, dtype=float)
    if F.ndim != 3 or r.ndim != 3 or r.shape[:2] != F.shape[:2] or r.shape[2] not in (2, 3):
        raise ValueError(f"F, r_contacts: shapes {F.shape}, {r.shape}; expected (N, m, p) and (N, m, npos), npos 2 or 3")
    N, m = F.shape[:2]
    P = m * (m - 1) // 2
    work = squeeze_workspace(m, r.shape[2], np.zeros(P) if desired is None else desired)
    out = np.full((N, P), np.nan)
    for n in range(N):
        pair_squeeze_into(r[n], F[n], *work, out[n])
    return out
