"""The virtual-linkage squeeze of a whole run, vectorized over the samples (post-processing)."""

from __future__ import annotations

import numpy as np

from coopctrl.load_distribution.grasp_matrix import pair_tensions


def squeeze_series(F, r_contacts, r_object, space: str, desired=None) -> np.ndarray:
    """Squeeze [N] per sample and contact pair of the contact wrenches ``F`` (N, m, k).

    Per sample: the internal part ``f_int = F - G^+ G F`` (the Moore-Penrose split of the same
    resultant, ``G`` the grasp matrix at the contacts ``r_contacts`` (N, m, npos) [m] about
    ``r_object`` (N, npos) [m]), decomposed on the virtual-linkage columns ``E`` by
    :func:`~coopctrl.load_distribution.grasp_matrix.pair_tensions`:
    ``s = s_des + E^+ (f_int - E s_des)``, ``s_des = desired`` (P,) [N] (zeros if None). Where the
    pairs are independent (two contacts, three non-collinear) this is ``E^+ f_int`` whatever
    ``desired``; for more contacts it is the tensions nearest the setpoint, so that ``s - s_des`` is
    the internal-force error in pair tensions. NaN at samples whose decomposition is ill-conditioned.
    All samples are decomposed at once.
    """
    F = np.asarray(F, dtype=float)
    r = np.asarray(r_contacts, dtype=float)
    r0 = np.asarray(r_object, dtype=float)
    N, m, k = F.shape
    npairs = m * (m - 1) // 2
    if N == 0 or npairs == 0:
        return np.zeros((N, npairs))
    n = m * k
    G = np.zeros((N, k, n))
    d = r - r0[:, None, :]
    for i in range(m):
        G[:, :, k * i:k * (i + 1)] = np.eye(k)
        if space == "spatial":
            c = k * i
            G[:, 3, c + 1], G[:, 3, c + 2] = -d[:, i, 2], d[:, i, 1]
            G[:, 4, c + 0], G[:, 4, c + 2] = d[:, i, 2], -d[:, i, 0]
            G[:, 5, c + 0], G[:, 5, c + 1] = -d[:, i, 1], d[:, i, 0]
        else:
            G[:, 2, k * i], G[:, 2, k * i + 1] = -d[:, i, 1], d[:, i, 0]
    f = F.reshape(N, n)
    Gf = np.einsum("sij,sj->si", G, f)
    f_int = f - np.einsum("sij,sj->si", np.linalg.pinv(G), Gf)
    E = np.zeros((N, n, npairs))
    npos = r.shape[2]
    col = 0
    for i in range(m):
        for j in range(i + 1, m):
            t = r[:, j] - r[:, i]
            with np.errstate(divide="ignore", invalid="ignore"):  # coincident contacts: NaN, reported as such
                t = t / np.linalg.norm(t, axis=1)[:, None]
            E[:, k * i:k * i + npos, col] = t
            E[:, k * j:k * j + npos, col] = -t
            col += 1
    return pair_tensions(E, f_int, desired)
