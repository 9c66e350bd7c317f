"""numba kernels of the per-tick controller arithmetic (the hot path of the closed loop).

Each is the compiled form of a documented Python-level law: :func:`node_torque` of
:func:`coopctrl.controllers.computed_torque.node_computed_torque`, :func:`pose_increment_spatial`
and :func:`pose_increment_planar` of :meth:`GraspCompliance.pose_increment`. Tests compare them
with plain numpy versions.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.frames import body_rate_map_inverse, rotation_zyx


@njit(cache=True)
def lu_solve(A, b):
    """Solve the small square system ``A x = b`` by Gaussian elimination with partial pivoting.

    Returns ``(x, ok)``; ``ok`` is False for a (numerically) singular ``A``.
    """
    n = A.shape[0]
    M = A.copy()
    x = b.copy()
    scale = 0.0
    for i in range(n):
        for j in range(n):
            scale = max(scale, abs(M[i, j]))
    tiny = 1e-13 * (scale if scale > 0 else 1.0)
    for c in range(n):
        p = c
        for r in range(c + 1, n):
            if abs(M[r, c]) > abs(M[p, c]):
                p = r
        if abs(M[p, c]) <= tiny:
            return x, False
        if p != c:
            for j in range(n):
                M[c, j], M[p, j] = M[p, j], M[c, j]
            x[c], x[p] = x[p], x[c]
        for r in range(c + 1, n):
            f = M[r, c] / M[c, c]
            if f != 0.0:
                for j in range(c, n):
                    M[r, j] -= f * M[c, j]
                x[r] -= f * x[c]
    for c in range(n - 1, -1, -1):
        s = x[c]
        for j in range(c + 1, n):
            s -= M[c, j] * x[j]
        x[c] = s / M[c, c]
    return x, True


@njit(cache=True)
def node_torque(W, w_free, S, H, h, J, Jdq, a_cmd, contact_point):
    """``tau = H J^-1 (a - Jdq) + h + J^T (W a + w_free + S)``; a contact point gets ``W a + w``.

    Returns ``(tau, ok)``; ``ok`` is False when ``J`` is singular (square arms only).
    """
    p = a_cmd.shape[0]
    F = np.empty(p)
    for r in range(p):
        s = w_free[r] + S[r]
        for c in range(p):
            s += W[r, c] * a_cmd[c]
        F[r] = s
    if contact_point:
        return F, True
    n = H.shape[0]
    rhs = a_cmd - Jdq
    qdd, ok = lu_solve(J, rhs)
    tau = np.empty(n)
    for r in range(n):
        s = h[r]
        for c in range(n):
            s += H[r, c] * qdd[c]
        for c in range(p):
            s += J[c, r] * F[c]
        tau[r] = s
    return tau, ok


@njit(cache=True)
def pose_increment_spatial(C, F_world, A0, Ai):
    """Node pose increment for wrench ``F_world`` through compliance ``C`` (object frame), spatial.

    ``d = C R0^T F``; ``dr = R0 d[:3]``; ``dA = L(A_i)^-1 R_i^T R0 d[3:]``. Returns ``(dY, ok)``.
    """
    R0 = rotation_zyx(A0)
    Fo = np.empty(6)
    for a in range(3):
        Fo[a] = R0[0, a] * F_world[0] + R0[1, a] * F_world[1] + R0[2, a] * F_world[2]
        Fo[3 + a] = R0[0, a] * F_world[3] + R0[1, a] * F_world[4] + R0[2, a] * F_world[5]
    d = C @ Fo
    out = np.empty(6)
    dth = np.empty(3)
    for a in range(3):
        out[a] = R0[a, 0] * d[0] + R0[a, 1] * d[1] + R0[a, 2] * d[2]
        dth[a] = R0[a, 0] * d[3] + R0[a, 1] * d[4] + R0[a, 2] * d[5]
    Ri = rotation_zyx(Ai)
    wb = Ri.T @ dth
    Linv = np.empty((3, 3))
    ok = body_rate_map_inverse(Ai, Linv)
    if not ok:
        out[3:] = 0.0
        return out, False
    dA = Linv @ wb
    out[3:] = dA
    return out, True


@njit(cache=True)
def pose_increment_planar(C, F_world, theta0):
    """Planar node pose increment: ``d = C R(theta0)^T F``, position rotated back to the world."""
    c, s = math.cos(theta0), math.sin(theta0)
    Fo = np.array([c * F_world[0] + s * F_world[1], -s * F_world[0] + c * F_world[1], F_world[2]])
    d = C @ Fo
    return np.array([c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]])


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
    F = np.empty(p)
    for r in range(p):
        s = w_free[r] + S[r]
        for c in range(p):
            s += W[r, c] * a_cmd[c]
        F[r] = s
    Nm = H + J.T @ (W @ J)
    # X = N^-1 J^T (n x p), A = J X = J N^-1 J^T (p x p)
    X = np.empty((n, p))
    col = np.empty(n)
    for c in range(p):
        for r in range(n):
            col[r] = J[c, r]
        x, ok = lu_solve(Nm, col)
        if not ok:
            return np.zeros(n), False
        for r in range(n):
            X[r, c] = x[r]
    A = J @ X
    y, ok = lu_solve(A, a_cmd - Jdq)
    if not ok:
        return np.zeros(n), False
    qdd = X @ y
    # null space: tau_0 - J^T A^-1 X^T tau_0  (X^T = J N^-1)
    z, ok = lu_solve(A, X.T @ tau_posture)
    if not ok:
        return np.zeros(n), False
    tau = h + H @ qdd + J.T @ F + tau_posture - J.T @ z
    return tau, True
