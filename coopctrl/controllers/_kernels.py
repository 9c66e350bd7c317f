"""numba kernels of the per-tick controller arithmetic (the hot path of the closed loop).

Each is the compiled form of a documented Python-level law: :func:`node_torque` of
:func:`coopctrl.controllers.computed_torque.node_computed_torque`, :func:`pose_increment_spatial`
and :func:`pose_increment_planar` of :meth:`GraspCompliance.pose_increment`. Tests compare them
with plain numpy versions.

Allocation-free forms (issue 10, the compiled tick): each ``*_into`` kernel writes its result into
an output argument and works in scratch arrays made once per run by :func:`control_work`
(``wv`` (``WORK_VECTORS``, nmax) vectors, ``wm`` (``WORK_MATRICES``, nmax, nmax) matrices, ``nmax``
>= the task dimension p and every arm's dof) and :func:`pose_work`. The functions without ``_into``
allocate their work and call them, so both run the same arithmetic.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.frames import body_rate_map_inverse, rotation_zyx_into

#: Rows of the vector scratch ``wv`` and matrices of ``wm`` that :func:`control_work` makes.
WORK_VECTORS = 8
WORK_MATRICES = 4


def control_work(nmax: int):
    """Scratch ``(wv, wm)`` for :func:`node_torque_into`, :func:`node_torque_redundant_into` and
    :func:`consistent_acceleration_into` with arms of up to ``nmax`` joints (``nmax >= p``)."""
    return np.empty((WORK_VECTORS, nmax)), np.empty((WORK_MATRICES, nmax, nmax))


def pose_work():
    """Scratch ``(R, v)`` for :func:`pose_increment_spatial_into`: (3, 3, 3) and (3, 6)."""
    return np.empty((3, 3, 3)), np.empty((3, 6))


@njit(cache=True)
def lu_factor_into(A, n, M, piv):
    """Gaussian elimination with partial pivoting of ``A[:n, :n]`` into ``M`` (the multipliers below
    the diagonal, ``U`` above it and the reciprocals ``1 / U_cc`` on it) and the row swaps ``piv[:n]``.
    Returns False for a (numerically) singular ``A`` (a pivot ``<= 1e-13 max|A|``)."""
    scale = 0.0
    for i in range(n):
        for j in range(n):
            v = A[i, j]
            M[i, j] = v
            scale = max(scale, abs(v))
    tiny = 1e-13 * (scale if scale > 0 else 1.0)
    for c in range(n):
        p = c
        for r in range(c + 1, n):
            if abs(M[r, c]) > abs(M[p, c]):
                p = r
        piv[c] = p
        if abs(M[p, c]) <= tiny:
            return False
        if p != c:
            for j in range(n):
                M[c, j], M[p, j] = M[p, j], M[c, j]
        inv = 1.0 / M[c, c]
        M[c, c] = inv
        for r in range(c + 1, n):
            f = M[r, c] * inv
            for j in range(c + 1, n):
                M[r, j] -= f * M[c, j]
            M[r, c] = f
    return True


@njit(cache=True)
def lu_solve_factored_into(M, piv, n, b, x):
    """``x[:n] = A^-1 b`` from :func:`lu_factor_into`'s ``(M, piv)`` (``b`` and ``x`` may alias)."""
    for i in range(n):
        x[i] = b[i]
    for c in range(n):
        p = piv[c]
        if p != c:
            x[c], x[p] = x[p], x[c]
    for c in range(n):
        xc = x[c]
        for r in range(c + 1, n):
            x[r] -= M[r, c] * xc
    for c in range(n - 1, -1, -1):
        s = x[c]
        for j in range(c + 1, n):
            s -= M[c, j] * x[j]
        x[c] = s * M[c, c]


@njit(cache=True)
def lu_solve_into(A, b, n, M, piv, x):
    """Solve ``A[:n, :n] x = b[:n]`` into ``x`` (``M`` (>= n, >= n) and ``piv`` (>= n, int) scratch).

    Returns False (``x`` unspecified) for a (numerically) singular ``A``.
    """
    if not lu_factor_into(A, n, M, piv):
        return False
    lu_solve_factored_into(M, piv, n, b, x)
    return True


@njit(cache=True)
def lu_solve(A, b):
    """Solve the small square system ``A x = b`` by Gaussian elimination with partial pivoting.

    Returns ``(x, ok)``; ``ok`` is False for a (numerically) singular ``A``.
    """
    n = A.shape[0]
    x = np.zeros(n)
    ok = lu_solve_into(A, b, n, np.empty((n, n)), np.empty(n, np.int64), x)
    return x, ok


@njit(cache=True)
def _node_wrench(W, w_free, S, a_cmd, F):
    """``F = W a + w_free + S`` (the node's wrench on the arm) [N, N m]."""
    p = a_cmd.shape[0]
    for r in range(p):
        s = w_free[r] + S[r]
        for c in range(p):
            s += W[r, c] * a_cmd[c]
        F[r] = s


@njit(cache=True)
def node_torque_into(W, w_free, S, H, h, J, Jdq, a_cmd, contact_point, n, wv, wm, piv, tau):
    """:func:`node_torque` into ``tau[:n]`` (a contact point: ``tau[:p]``) for an arm of ``n`` joints
    (``H[:n, :n]``, ``h[:n]``, ``J[:, :n]`` are read). Returns ``ok``."""
    p = a_cmd.shape[0]
    F = wv[0]
    _node_wrench(W, w_free, S, a_cmd, F)
    if contact_point:
        for r in range(p):
            tau[r] = F[r]
        return True
    rhs = wv[1]
    qdd = wv[2]
    for r in range(p):
        rhs[r] = a_cmd[r] - Jdq[r]
    ok = lu_solve_into(J, rhs, n, wm[0], piv, qdd)
    if not ok:
        for c in range(n):
            qdd[c] = 0.0
    for r in range(n):
        s = h[r]
        for c in range(n):
            s += H[r, c] * qdd[c]
        for c in range(p):
            s += J[c, r] * F[c]
        tau[r] = s
    return ok


@njit(cache=True)
def node_torque(W, w_free, S, H, h, J, Jdq, a_cmd, contact_point):
    """``tau = H J^-1 (a - Jdq) + h + J^T (W a + w_free + S)``; a contact point gets ``W a + w``.

    Returns ``(tau, ok)``; ``ok`` is False when ``J`` is singular (square arms only).
    """
    p = a_cmd.shape[0]
    n = H.shape[0]
    nmax = max(n, p)
    tau = np.empty(p if contact_point else n)
    ok = node_torque_into(W, w_free, S, H, h, J, Jdq, a_cmd, contact_point, n, np.empty((WORK_VECTORS, nmax)),
                          np.empty((WORK_MATRICES, nmax, nmax)), np.empty(nmax, np.int64), tau)
    return tau, ok


@njit(cache=True)
def consistent_acceleration_into(W, H, J, rhs, n, wv, wm, piv, qdd):
    """``qdd = J^# rhs`` with the inertia-weighted generalized inverse of a redundant arm:
    ``N = H + J^T W J`` (``wm[0]``), ``X = N^-1 J^T`` (``wm[1][:n, :p]``), ``A = J X`` (``wm[2][:p, :p]``,
    factored into ``wm[3]`` with its swaps in ``piv``), ``qdd = X A^-1 rhs`` (``qdd[:n]``).
    Returns False (``qdd`` zero) when ``N`` or ``A`` is singular. ``wv`` rows 1, 2 are scratch;
    ``rhs[:p]`` is read (p = rows of ``J``)."""
    p = J.shape[0]
    Nm = wm[0]
    X = wm[1]
    A = wm[2]
    LU = wm[3]
    WJ = wm[2]
    for a in range(p):
        for c in range(n):
            t = 0.0
            for b in range(p):
                t += W[a, b] * J[b, c]
            WJ[a, c] = t
    for r in range(n):
        for c in range(r + 1):  # J^T W J is symmetric (W is): the lower triangle, mirrored
            s = 0.0
            for a in range(p):
                s += J[a, r] * WJ[a, c]
            Nm[r, c] = H[r, c] + s
            Nm[c, r] = H[c, r] + s
    col = wv[1]
    if not lu_factor_into(Nm, n, LU, piv):
        for c in range(n):
            qdd[c] = 0.0
        return False
    for c in range(p):
        for r in range(n):
            col[r] = J[c, r]
        lu_solve_factored_into(LU, piv, n, col, col)
        for r in range(n):
            X[r, c] = col[r]
    for a in range(p):
        for c in range(p):
            s = 0.0
            for r in range(n):
                s += J[a, r] * X[r, c]
            A[a, c] = s
    y = wv[2]
    if not lu_factor_into(A, p, LU, piv):
        for c in range(n):
            qdd[c] = 0.0
        return False
    lu_solve_factored_into(LU, piv, p, rhs, y)
    for r in range(n):
        s = 0.0
        for c in range(p):
            s += X[r, c] * y[c]
        qdd[r] = s
    return True


@njit(cache=True)
def node_torque_redundant_into(W, w_free, S, H, h, J, Jdq, a_cmd, tau_posture, n, wv, wm, piv, tau):
    """:func:`node_torque_redundant` into ``tau[:n]`` for an arm of ``n > p`` joints. Returns ``ok``
    (``tau`` zero when False)."""
    p = a_cmd.shape[0]
    F = wv[0]
    _node_wrench(W, w_free, S, a_cmd, F)
    rhs = wv[3]
    for r in range(p):
        rhs[r] = a_cmd[r] - Jdq[r]
    qdd = wv[4]
    if not consistent_acceleration_into(W, H, J, rhs, n, wv, wm, piv, qdd):
        for c in range(n):
            tau[c] = 0.0
        return False
    # null space: tau_0 - J^T A^-1 X^T tau_0  (X^T = J N^-1); A is factored in wm[3], piv
    X = wm[1]
    z = wv[5]
    for c in range(p):
        s = 0.0
        for r in range(n):
            s += X[r, c] * tau_posture[r]
        z[c] = s
    lu_solve_factored_into(wm[3], piv, p, z, z)
    for r in range(n):
        s = 0.0
        for c in range(n):
            s += H[r, c] * qdd[c]
        jf = 0.0
        jz = 0.0
        for a in range(p):
            jf += J[a, r] * F[a]
            jz += J[a, r] * z[a]
        tau[r] = (((h[r] + s) + jf) + tau_posture[r]) - jz
    return True


@njit(cache=True)
def node_torque_redundant(W, w_free, S, H, h, J, Jdq, a_cmd, tau_posture):
    """Computed torque of a redundant arm (``n > p``) plus a null-space posture torque.

    .. math::
        N = H + J^T W J, \\quad J^\\# = N^{-1} J^T (J N^{-1} J^T)^{-1}, \\quad
        \\ddot q = J^\\# (a - \\dot J \\dot q),

        \\tau = H \\ddot q + h + J^T (W a + w_{free} + S) + (I - J^T J^{\\#T})\\, \\tau_0

    ``J^#`` is the inertia-weighted (dynamically consistent) generalized inverse, so the
    null-space torque ``(I - J^T J^{#T}) tau_0`` gives the node no acceleration
    (``J N^-1 (I - J^T J^{#T}) = 0``). Returns ``(tau, ok)``; ``ok`` is False when ``N`` or
    ``J N^-1 J^T`` is singular.
    """
    p = a_cmd.shape[0]
    n = H.shape[0]
    nmax = max(n, p)
    tau = np.empty(n)
    ok = node_torque_redundant_into(W, w_free, S, H, h, J, Jdq, a_cmd, tau_posture, n, np.empty((WORK_VECTORS, nmax)),
                                    np.empty((WORK_MATRICES, nmax, nmax)), np.empty(nmax, np.int64), tau)
    return tau, ok


@njit(cache=True)
def pose_increment_spatial_into(C, F_world, A0, Ai, R, v, out):
    """:func:`pose_increment_spatial` into ``out`` (6); ``R`` (3, 3, 3) and ``v`` (3, 6) scratch.
    Returns ``ok`` (False: ``out[3:]`` zero, ``L(A_i)`` singular)."""
    R0 = R[0]
    Ri = R[1]
    Linv = R[2]
    Fo = v[0]
    d = v[1]
    dth = v[2]
    rotation_zyx_into(A0, R0)
    for a in range(3):
        Fo[a] = R0[0, a] * F_world[0] + R0[1, a] * F_world[1] + R0[2, a] * F_world[2]
        Fo[3 + a] = R0[0, a] * F_world[3] + R0[1, a] * F_world[4] + R0[2, a] * F_world[5]
    for a in range(6):
        s = 0.0
        for b in range(6):
            s += C[a, b] * Fo[b]
        d[a] = s
    for a in range(3):
        out[a] = R0[a, 0] * d[0] + R0[a, 1] * d[1] + R0[a, 2] * d[2]
        dth[a] = R0[a, 0] * d[3] + R0[a, 1] * d[4] + R0[a, 2] * d[5]
    if not body_rate_map_inverse(Ai, Linv):
        for a in range(3):
            out[3 + a] = 0.0
        return False
    rotation_zyx_into(Ai, Ri)
    wb = v[0]  # Fo is no longer needed
    for a in range(3):
        wb[a] = Ri[0, a] * dth[0] + Ri[1, a] * dth[1] + Ri[2, a] * dth[2]
    for a in range(3):
        out[3 + a] = Linv[a, 0] * wb[0] + Linv[a, 1] * wb[1] + Linv[a, 2] * wb[2]
    return True


@njit(cache=True)
def pose_increment_spatial(C, F_world, A0, Ai):
    """Node pose increment for wrench ``F_world`` through compliance ``C`` (object frame), spatial.

    ``d = C R0^T F``; ``dr = R0 d[:3]``; ``dA = L(A_i)^-1 R_i^T R0 d[3:]``. Returns ``(dY, ok)``.
    """
    out = np.empty(6)
    ok = pose_increment_spatial_into(C, F_world, A0, Ai, np.empty((3, 3, 3)), np.empty((3, 6)), out)
    return out, ok


@njit(cache=True)
def pose_increment_planar_into(C, F_world, theta0, out):
    """:func:`pose_increment_planar` into ``out`` (3)."""
    c, s = math.cos(theta0), math.sin(theta0)
    f0 = c * F_world[0] + s * F_world[1]
    f1 = -s * F_world[0] + c * F_world[1]
    f2 = F_world[2]
    d0 = C[0, 0] * f0 + C[0, 1] * f1 + C[0, 2] * f2
    d1 = C[1, 0] * f0 + C[1, 1] * f1 + C[1, 2] * f2
    d2 = C[2, 0] * f0 + C[2, 1] * f1 + C[2, 2] * f2
    out[0] = c * d0 - s * d1
    out[1] = s * d0 + c * d1
    out[2] = d2


@njit(cache=True)
def pose_increment_planar(C, F_world, theta0):
    """Planar node pose increment: ``d = C R(theta0)^T F``, position rotated back to the world."""
    out = np.empty(3)
    pose_increment_planar_into(C, F_world, theta0, out)
    return out
