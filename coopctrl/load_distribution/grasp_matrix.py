"""Grasp matrix, internal-force bases (null space, virtual linkage) and pair tensions (docs/model.md section 6).

A contact wrench ``F_i`` [N, N m] is applied by arm i to the object at the contact point
``r_i`` [m], in world coordinates. The object mass centre is ``r_0`` [m].

Spatial scenes (``space="spatial"``, wrench dimension 6, ``F_i = (f_i, n_i)``):

.. math::

    G_i = \\begin{bmatrix} I_3 & 0 \\\\ S(r_i - r_0) & I_3 \\end{bmatrix}, \\qquad
    G = [G_1 \\; \\cdots \\; G_m] \\in \\mathbb{R}^{6 \\times 6m},

with ``S(a) b = a x b``. Planar scenes (``space="planar"``, vertical x-z plane, ``F_i = (f_x, f_z, n)``,
``theta`` from +x toward +z):

.. math::

    G_i = \\begin{bmatrix} 1 & 0 & 0 \\\\ 0 & 1 & 0 \\\\ -(r_{iz} - r_{0z}) & r_{ix} - r_{0x} & 1
    \\end{bmatrix}, \\qquad n_{total} = \\sum_i (d_x f_z - d_z f_x) + n_i .

**Internal load (virtual linkage).** For every pair ``(i, j)``, ``i < j`` (pairs in lexicographic
order), the unit squeeze column ``e_ij`` of ``E`` puts the force ``+t_ij`` on contact i and
``-t_ij`` on contact j, with

.. math::

    t_{ij} = \\frac{r_j - r_i}{\\lVert r_j - r_i \\rVert}, \\qquad G e_{ij} = 0 .

Positive squeeze ``s_ij > 0`` means both arms push the object toward each other (compression);
negative means they pull it apart (tension). The moments of ``e_ij`` are zero.

The pair columns span the *force-only* internal loads along the lines joining the contacts. They are
independent for two contacts, for three non-collinear contacts, and (spatial) for four non-coplanar
ones; beyond that (``m(m-1)/2`` pairs against ``2m - 3`` planar or ``3m - 6`` spatial force-only
internal directions) they are dependent, and pair tensions of a given internal load are not unique.

**Null-space basis (any m).** :func:`internal_null_basis` returns an orthonormal basis ``N``
(``n x k(m-1)``, ``N^T N = I``, ``G N = 0``) of the whole internal space ``null(G)``, forces and
moments, for any number of contacts: the columns that apply a unit wrench ``e_a`` (expressed at
contact 1) at contact j and its opposite at contact 1, ``j = 2..m``, orthonormalized by a Householder
QR. ``null(G)`` does not depend on the reference point ``r_0``.

**Pair tensions (any m).** :func:`pair_tensions` decomposes an internal load ``f_int`` on the pair
columns relative to the desired squeeze ``s_des``:

.. math::

    s = s_{des} + E^+ (f_{int} - E s_{des}),

with ``E^+`` the pseudo-inverse of the pair columns' numerical rank (a one-sided Jacobi singular value
decomposition, coopctrl/core/qp_tensions.h, as the compiled tick runs it): the
pair tensions nearest the setpoint (least ``||s - s_des||``) whose linkage forces ``E s`` match ``f_int`` best.
Where the pairs are independent, ``E^+ E = I`` and ``s = E^+ f_int`` (the unique pair tensions, whatever ``s_des``).
The rank is read from the singular values ``sigma`` of ``E``: ``sigma / sigma_max <= PAIR_ZERO_RTOL``
is a structural dependence (rounding), ``> PAIR_KEEP_RTOL`` a kept direction; a singular value in
between (contacts nearly collinear or nearly coincident) means the decomposition is ill-conditioned:
the tensions are reported as NaN (unavailable), never computed from it.

**No internal load.** A split ``F`` carries no internal load when it lies in the range of
``W^{-1} G^T`` (the weighted pseudo-inverse split ``F = W^{-1} G^T (G W^{-1} G^T)^{-1} w`` is the
one that is W-orthogonal to ``null(G)``). With equal isotropic weights this is the Euclidean
pseudo-inverse split, whose virtual-linkage squeeze ``E^+ F`` is zero.
"""

from __future__ import annotations

import numpy as np

from ..errors import ScenarioError

#: Wrench dimension per contact for each kind of scene.
WRENCH_DIM = {"spatial": 6, "planar": 3}
#: Position dimension per contact for each kind of scene.
POSITION_DIM = {"spatial": 3, "planar": 2}


def wrench_dim(space: str) -> int:
    """Wrench dimension (6 spatial, 3 planar) of a scene kind; raise ``ScenarioError`` otherwise."""
    try:
        return WRENCH_DIM[space]
    except KeyError:
        raise ScenarioError("space", space, "'spatial' or 'planar'") from None


def contact_pairs(m: int) -> list[tuple[int, int]]:
    """All pairs ``(i, j)``, ``i < j``, of ``m`` contacts, in lexicographic order."""
    return [(i, j) for i in range(m) for j in range(i + 1, m)]


def _positions(r_contacts, r_object, space: str) -> tuple[np.ndarray, np.ndarray]:
    p = POSITION_DIM[space] if space in POSITION_DIM else None
    if p is None:
        raise ScenarioError("space", space, "'spatial' or 'planar'")
    r = np.asarray(r_contacts, dtype=float)
    r0 = np.asarray(r_object, dtype=float)
    if r.ndim != 2 or r.shape[1] != p:
        raise ScenarioError("r_contacts", r.shape, f"an array of shape (m, {p}) [m]")
    if r0.shape != (p,):
        raise ScenarioError("r_object", r0.shape, f"an array of shape ({p},) [m]")
    return r, r0


def fill_grasp_matrix(G: np.ndarray, r: np.ndarray, r0: np.ndarray, space: str) -> None:
    """Write the moment-arm entries of ``G`` in place (the identity blocks must already be set): the
    formula of the C++ core's ``fill_grasp_rows`` (coopctrl/core/qp_assembly.h), in numpy.

    Args:
        G: Preallocated grasp matrix (6 × 6m or 3 × 3m), C-contiguous float64, whose identity blocks are set.
        r: Contact points (m × 3 or m × 2) [m].
        r0: Object mass centre [m].
        space: ``"spatial"`` or ``"planar"``.
    """
    from coopctrl._core import fill_grasp_rows  # here: importing the package (scenario validation) loads no core

    k, m = WRENCH_DIM[space], r.shape[0]
    if G.shape != (k, k * m) or G.dtype != np.float64:
        raise ValueError(f"G: shape {G.shape}, dtype {G.dtype}; expected float64 of shape ({k}, {k * m})")
    fill_grasp_rows(G, np.array(r, dtype=float, order="C"), np.array(r0, dtype=float, order="C"), space == "spatial")


def identity_grasp_matrix(m: int, space: str) -> np.ndarray:
    """Grasp matrix with only the identity blocks set (all moment arms zero)."""
    k = wrench_dim(space)
    G = np.zeros((k, k * m))
    for i in range(m):
        G[:, k * i:k * (i + 1)] = np.eye(k)
    return G


def grasp_matrix(r_contacts, r_object, space: str) -> np.ndarray:
    """Grasp matrix ``G = [G_1 ... G_m]`` mapping contact wrenches to the object wrench at ``r_0``.

    Args:
        r_contacts: Contact points ``r_i``, shape (m, 3) spatial or (m, 2) planar (x, z) [m].
        r_object: Object mass centre ``r_0``, shape (3,) or (2,) [m].
        space: ``"spatial"`` or ``"planar"``.

    Returns:
        ``G``, shape (6, 6m) or (3, 3m), such that ``w = G F`` for the stacked wrenches ``F``.
    """
    r, r0 = _positions(r_contacts, r_object, space)
    G = identity_grasp_matrix(r.shape[0], space)
    fill_grasp_matrix(G, r, r0, space)
    return G


def fill_internal_force_basis(E: np.ndarray, r: np.ndarray, space: str) -> None:
    """Write the virtual-linkage squeeze columns into a preallocated zero ``E`` (n × pairs, C-contiguous
    float64): the formula of the C++ core's ``fill_squeeze_basis`` (coopctrl/core/qp_assembly.h), in numpy.

    Only the force entries are written; the moment entries stay zero. Raises
    ``ScenarioError`` if two contacts coincide (the squeeze direction is undefined).
    """
    from coopctrl._core import fill_squeeze_basis  # here: importing the package (scenario validation) loads no core

    r = np.array(r, dtype=float, order="C")
    k, m = WRENCH_DIM[space], r.shape[0]
    if E.shape != (k * m, m * (m - 1) // 2) or E.dtype != np.float64:
        raise ValueError(f"E: shape {E.shape}, dtype {E.dtype}; expected float64 of shape ({k * m}, {m * (m - 1) // 2})")
    if not fill_squeeze_basis(E, r, k):
        raise ScenarioError("r_contacts", closest_pair(r), "distinct contact points (pair coincides)")


def closest_pair(r: np.ndarray) -> tuple[int, int]:
    """The pair ``(i, j)``, ``i < j``, of the closest contacts ``r`` (m >= 2): the one to name when the
    squeeze basis finds coincident contacts."""
    pairs = contact_pairs(r.shape[0])
    d = [float(np.sum((r[j] - r[i]) ** 2)) for i, j in pairs]
    return pairs[int(np.argmin(d))]


def internal_force_basis(r_contacts, space: str) -> np.ndarray:
    """Virtual-linkage internal-force basis ``E`` (one unit-squeeze column per contact pair).

    Column ``e_ij`` (pairs ``i < j`` in lexicographic order) applies ``+t_ij`` on contact i and
    ``-t_ij`` on contact j, ``t_ij = (r_j - r_i)/|r_j - r_i|``: a positive coefficient squeezes the
    object (both contacts push toward each other). ``G E = 0`` for any object point ``r_0``.

    Args:
        r_contacts: Contact points, shape (m, 3) or (m, 2) [m].
        space: ``"spatial"`` or ``"planar"``.

    Returns:
        ``E``, shape (6m, m(m-1)/2) or (3m, m(m-1)/2) [N per N of squeeze].
    """
    k = wrench_dim(space)
    r = np.asarray(r_contacts, dtype=float)
    if r.ndim != 2 or r.shape[1] != POSITION_DIM[space]:
        raise ScenarioError("r_contacts", r.shape, f"an array of shape (m, {POSITION_DIM[space]}) [m]")
    m = r.shape[0]
    E = np.zeros((k * m, m * (m - 1) // 2))
    fill_internal_force_basis(E, r, space)
    return E


#: Singular values of the pair columns at or below this fraction of the largest are a structural
#: dependence (rounding: about 1e-15 for dependent pairs), ignored by :func:`pair_tensions`.
PAIR_ZERO_RTOL = 1e-10
#: Singular values above this fraction of the largest are kept; between the two tolerances the
#: decomposition is ill-conditioned (it would amplify the forces' rounding by more than 1e6) and
#: :func:`pair_tensions` reports NaN.
PAIR_KEEP_RTOL = 1e-6


def internal_null_basis(r_contacts, space: str) -> np.ndarray:
    """Orthonormal basis ``N`` of the internal loads ``null(G)`` for any number of contacts.

    Columns ``j = 2..m``, ``a = 1..k`` apply the wrench ``T_j^{-1} e_a`` at contact j and
    ``-T_1^{-1} e_a`` at contact 1 (``T_i`` the block ``G_i`` taken about contact 1, so that the
    column's resultant is ``e_a - e_a = 0``); a Householder QR makes them orthonormal. The internal
    space does not depend on the object point ``r_0``, so none is taken.

    Args:
        r_contacts: Contact points, shape (m, 3) spatial or (m, 2) planar [m], m >= 1.
        space: ``"spatial"`` or ``"planar"``.

    Returns:
        ``N``, shape (k m, k (m - 1)), ``N^T N = I``, ``G N = 0`` [N per unit coordinate].
    """
    k = wrench_dim(space)
    r = np.asarray(r_contacts, dtype=float)
    p = POSITION_DIM[space]
    if r.ndim != 2 or r.shape[1] != p or r.shape[0] < 1:
        raise ScenarioError("r_contacts", r.shape, f"an array of shape (m, {p}), m >= 1 [m]")
    if not np.all(np.isfinite(r)):
        raise ScenarioError("r_contacts", r.tolist(), "finite contact points [m]")
    m = r.shape[0]
    G = grasp_matrix(r, r[0], space)
    B = np.zeros((k * m, k * (m - 1)))
    T0_inv = np.linalg.inv(G[:, :k])  # the identity: contact 1 is the reference point
    for j in range(1, m):
        Tj_inv = np.linalg.inv(G[:, k * j:k * (j + 1)])  # unit determinant: always invertible
        B[k * j:k * (j + 1), k * (j - 1):k * j] = Tj_inv
        B[:k, k * (j - 1):k * j] = -T0_inv
    if B.shape[1] == 0:
        return B
    Q, _ = np.linalg.qr(B)
    return Q


def pair_tensions(E, F_internal, desired=None) -> np.ndarray:
    """Pair tensions ``s = s_des + E^+ (F_int - E s_des)`` [N], for one sample or a batch.

    ``E^+`` is the pseudo-inverse of the numerical rank of the pair columns (see the module
    docstring): where the pairs are independent this is ``E^+ F_int``, the unique pair tensions;
    where they are dependent (planar m >= 4, spatial m >= 5 or coplanar contacts) it is the solution
    nearest ``s_des``. A sample whose pair columns are ill-conditioned (a singular value between
    :data:`PAIR_ZERO_RTOL` and :data:`PAIR_KEEP_RTOL` of the largest) or not finite gets NaN. The
    compiled ``pair_tensions_into`` (coopctrl/core/qp_tensions.h, one-sided Jacobi), which the loop's squeeze
    runs too.

    Args:
        E: Pair columns, (n, P) or (N, n, P) (:func:`internal_force_basis`).
        F_internal: Internal loads, (n,) or (N, n) [N, N m].
        desired: Desired squeeze ``s_des`` (P,) [N]; None for zeros (then the minimum-norm tensions).

    Returns:
        ``s``, (P,) or (N, P) [N].
    """
    E = np.asarray(E, dtype=float)
    f = np.asarray(F_internal, dtype=float)
    single = E.ndim == 2
    if single:
        E, f = E[None], f.reshape(1, -1)
    N, n, P = E.shape
    if f.shape != (N, n):
        raise ValueError(f"F_internal: shape {f.shape}; expected ({N}, {n}) like E's rows")
    s_des = np.zeros(P) if desired is None else np.asarray(desired, dtype=float).reshape(-1)
    if s_des.shape != (P,):
        raise ValueError(f"desired: shape {s_des.shape}; expected ({P},), one squeeze per pair")
    s = np.full((N, P), np.nan)
    if P == 0 or N == 0:
        return s[0] if single else s
    from coopctrl._core import pair_tensions_into  # here: importing the package (scenario validation) loads no core

    # sample by sample on the C++ core's pair_tensions_into (one scratch for all, NaN where a sample is not finite)
    E = np.ascontiguousarray(E)
    F = np.ascontiguousarray(f).reshape(N, n, 1)
    rows, cols = (n, P) if P <= n else (P, n)
    W, V, sigma = np.zeros((rows, cols)), np.zeros((cols, cols)), np.zeros(cols)
    finite = np.isfinite(E).all(axis=(1, 2)) & np.isfinite(F).all(axis=(1, 2))
    for k in range(N):
        if finite[k]:
            pair_tensions_into(E[k], F[k], 1, s_des, W, V, sigma, s[k])
    return s[0] if single else s


def virtual_linkage_squeeze(F_internal, r_contacts, space: str, desired=None) -> np.ndarray:
    """Virtual-linkage squeeze [N] per pair ``i < j`` of an internal load: :func:`pair_tensions`
    of ``F_int`` (stacked or (m, 6)/(m, 3)) on the columns of :func:`internal_force_basis`.

    Where the pairs are independent (two contacts, three non-collinear) it is the unique ``E^+ F_int``;
    where they are dependent (planar m >= 4, spatial m >= 5) the tensions nearest ``desired`` (the
    minimum-norm ones if None). NaN where the decomposition is ill-conditioned. Internal moments and
    shear are not squeeze and do not show here.
    """
    F = np.asarray(F_internal, dtype=float).ravel()
    E = internal_force_basis(r_contacts, space)
    if E.shape[1] == 0:
        return np.zeros(0)
    return pair_tensions(E, F, desired)
