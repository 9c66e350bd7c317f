"""The virtual-linkage squeeze of one tick: the compiled tick records it per tick (coopctrl/core/squeeze.h's
``pair_squeeze``, bound as :func:`pair_squeeze_into`), so a run's squeeze needs no post-processing.

The squeeze of the contact wrenches ``F`` (m, p) at the contacts ``r`` (m, npos) [m] is the pair
tensions of their internal part on the virtual-linkage columns ``E`` (the squeeze basis of
coopctrl/core/qp_assembly.h's ``fill_squeeze_basis``, docs/model.md section 6):

.. math::

    s = s_{des} + E^+ (f_{int} - E s_{des}), \\qquad f_{int} = F - G^+ G F .

Because ``G E = 0``, ``E^+ G^+ G = 0`` (``E^+`` maps through ``range(E)``, which is orthogonal to
``range(G^T)``): ``E^+ f_int = E^+ F``, so neither ``G`` nor the object point enters and

.. math::

    s = s_{des} + \\sum_{j\\ \\mathrm{kept}} v_j \\left( \\frac{w_j^T f}{\\sigma_j^2} - v_j^T s_{des} \\right),
    \\qquad E V = W = [w_1 \\cdots], \\; \\lVert w_j \\rVert = \\sigma_j ,

with ``f`` the force entries of ``F`` (the moment rows of ``E`` are zero) and ``V`` the rotations of a
one-sided Jacobi singular value decomposition of ``E`` (its force rows, ``R = m npos`` by
``P = m(m-1)/2``): coopctrl/core/qp_tensions.h's ``pair_tensions``, the one definition of the
pair tensions, which the public :func:`coopctrl.load_distribution.grasp_matrix.pair_tensions` runs too.
The tick's squeeze is NaN where the pairs are ill-conditioned, ``F`` or ``r`` is not finite or two contacts
coincide.

Per tick this is small fixed-size arithmetic on the work arrays of :func:`squeeze_workspace`, made
once per run: for two contacts one column (no rotation), for three a few rotations of three columns.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from coopctrl._core import pair_squeeze_into  # coopctrl/core/squeeze.h

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
