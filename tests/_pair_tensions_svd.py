"""The former numpy pair tensions (a batched LAPACK SVD), kept as the independent reference of the compiled
one-sided Jacobi of the compiled core (coopctrl/core/qp_tensions.h)."""

from __future__ import annotations

import numpy as np

from coopctrl.load_distribution.grasp_matrix import PAIR_KEEP_RTOL, PAIR_ZERO_RTOL


def svd_pair_tensions(E, F_internal, desired=None) -> np.ndarray:
    """``s = s_des + E^+ (f - E s_des)`` [N] per sample by the SVD of ``E`` (N, n, P) or (n, P), with the
    rank rules of ``pair_tensions`` (NaN where ill-conditioned or not finite)."""
    E = np.asarray(E, dtype=float)
    f = np.asarray(F_internal, dtype=float)
    single = E.ndim == 2
    if single:
        E, f = E[None], f.reshape(1, -1)
    N, n, P = E.shape
    s_des = np.zeros(P) if desired is None else np.asarray(desired, dtype=float).reshape(-1)
    s = np.full((N, P), np.nan)
    good = np.all(np.isfinite(E.reshape(N, -1)), axis=1) & np.all(np.isfinite(f), axis=1)
    Eg = E[good]
    U, S, Vt = np.linalg.svd(Eg, full_matrices=False)
    smax = S[:, :1]
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(smax > 0, S / smax, 0.0)
        keep = rel > PAIR_KEEP_RTOL
        ill = np.any((rel > PAIR_ZERO_RTOL) & ~keep, axis=1) | (smax[:, 0] <= 0)
        inv = np.where(keep, 1.0 / np.where(keep, S, 1.0), 0.0)
    resid = f[good] - np.einsum("sij,j->si", Eg, s_des)
    coef = inv * np.einsum("sji,sj->si", U, resid)
    sg = s_des[None, :] + np.einsum("sji,sj->si", Vt, coef)
    sg[ill] = np.nan
    s[good] = sg
    return s[0] if single else s
