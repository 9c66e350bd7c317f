"""Nominal motion of the loaded state (148): contact nodes carried rigidly by the object.

If the object moves rigidly, node j follows ``r_j = r_0 + R(A_0) rho_0j`` and its frame
``R_j = R(A_0) R(A_0j)``. The book writes the orientation as ``A_j = A_0 + A_0j``, which is
exact only when the rotations commute; we compose rotations and extract the ZYX angles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.frames import body_rate_map_inverse, check_euler, rotation_zyx_into


def nominal_node_poses(Y0, grasps, space: str = "spatial") -> np.ndarray:
    """Node poses ``(Y_0, Y_1..Y_m)`` (m+1, p) with every contact rigidly fixed to the object.

    Args:
        Y0: Object pose [m, rad] (6 spatial, 3 planar).
        grasps: (m, p) pose of each contact node in the object frame: offset ``rho_0j`` [m]
            and relative ZYX angles ``A_0j`` (planar: ``(dx, dz, dtheta)``).
        space: ``"spatial"`` or ``"planar"``.
    """
    return nominal_node_motion(Y0, np.zeros_like(np.asarray(Y0, float)), np.zeros_like(np.asarray(Y0, float)),
                               grasps, space)[0]


def nominal_node_motion(Y0, dY0, ddY0, grasps, space: str = "spatial"):
    """``(Y, dY, ddY)``, each (m+1, p), of the contact nodes carried rigidly by the object.

    .. math::
        r_j = r_0 + R_0 \\rho_{0j}, \\quad \\dot r_j = \\dot r_0 + \\omega \\times R_0 \\rho_{0j}, \\quad
        \\ddot r_j = \\ddot r_0 + \\alpha \\times R_0\\rho_{0j} + \\omega \\times (\\omega \\times R_0 \\rho_{0j})

    with world angular velocity ``omega = R_0 L(A_0) dA_0`` and ``alpha = R_0 (L ddA_0 + dL dA_0)``;
    each node's Euler rates follow from ``dA_j = L(A_j)^-1 R_j^T omega`` and
    ``ddA_j = L(A_j)^-1 (R_j^T alpha - dL_j dA_j)``. Raises
    :class:`~plants.errors.EulerSingularityError` if a node's frame is at pitch +-90 deg.
    """
    Y0 = np.ascontiguousarray(Y0, dtype=float)
    dY0 = np.ascontiguousarray(dY0, dtype=float)
    ddY0 = np.ascontiguousarray(ddY0, dtype=float)
    G = np.ascontiguousarray(np.atleast_2d(np.asarray(grasps, dtype=float)))
    from plants import _core

    p = 3 if space == "planar" else 6
    Y, dY, ddY = (np.empty((G.shape[0] + 1, p)) for _ in range(3))
    bad = _core.nominal_node_motion(Y0, dY0, ddY0, G, Y, dY, ddY)  # plants/core/rigid_motion.h
    if bad >= 0:
        check_euler(Y[bad, 3:], f"nominal pose of contact node {bad}")
    return Y, dY, ddY


@njit(cache=True)
def planar_motion_into(Y0, dY0, ddY0, G, Y, dY, ddY):
    """:func:`nominal_node_motion` (planar) into ``Y``, ``dY``, ``ddY`` (m+1, 3), allocation free."""
    m = G.shape[0]
    for a in range(3):
        Y[0, a] = Y0[a]
        dY[0, a] = dY0[a]
        ddY[0, a] = ddY0[a]
    th, w, al = Y0[2], dY0[2], ddY0[2]
    c, s = math.cos(th), math.sin(th)
    for j in range(m):
        d0 = c * G[j, 0] - s * G[j, 1]
        d1 = s * G[j, 0] + c * G[j, 1]
        Y[j + 1, 0] = Y0[0] + d0
        Y[j + 1, 1] = Y0[1] + d1
        Y[j + 1, 2] = th + G[j, 2]
        dY[j + 1, 0] = dY0[0] - w * d1
        dY[j + 1, 1] = dY0[1] + w * d0
        dY[j + 1, 2] = w
        ddY[j + 1, 0] = ddY0[0] - al * d1 - w * w * d0
        ddY[j + 1, 1] = ddY0[1] + al * d0 - w * w * d1
        ddY[j + 1, 2] = al


@njit(cache=True)
def body_rate_map_into(A, L):
    """:func:`plants.frames.body_rate_map` into ``L`` (3x3)."""
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    L[0, 0] = -sth
    L[0, 1] = 0.0
    L[0, 2] = 1.0
    L[1, 0] = sph * cth
    L[1, 1] = cph
    L[1, 2] = 0.0
    L[2, 0] = cph * cth
    L[2, 1] = -sph
    L[2, 2] = 0.0


@njit(cache=True)
def body_rates_into(A, dA, ddA, w, dw):
    """Body angular velocity ``w = L(A) dA`` and acceleration ``dw = L(A) ddA + dL(A, dA) dA``
    [rad/s, rad/s^2] of ZYX angles ``A`` (:func:`plants.frames.body_rate_map`, ``body_rate_map_dot``),
    into ``w`` and ``dw`` (3 each)."""
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    dth, dph = dA[1], dA[2]
    w[0] = -sth * dA[0] + dA[2]
    w[1] = sph * cth * dA[0] + cph * dA[1]
    w[2] = cph * cth * dA[0] - sph * dA[1]
    # L ddA + dL dA, row by row (dL: body_rate_map_dot)
    dw[0] = (-sth * ddA[0] + ddA[2]) + (-cth * dth) * dA[0]
    dw[1] = (sph * cth * ddA[0] + cph * ddA[1]) + ((cph * cth * dph - sph * sth * dth) * dA[0] + (-sph * dph) * dA[1])
    dw[2] = (cph * cth * ddA[0] - sph * ddA[1]) + ((-sph * cth * dph - cph * sth * dth) * dA[0] + (-cph * dph) * dA[1])


def motion_work():
    """Scratch ``(R, v)`` for :func:`spatial_motion_into`: (4, 3, 3) and (8, 3)."""
    return np.empty((4, 3, 3)), np.empty((8, 3))


@njit(cache=True)
def _cross_into(a, b, out):
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True)
def spatial_motion_into(Y0, dY0, ddY0, G, Y, dY, ddY, R, v):
    """:func:`nominal_node_motion` (spatial) into ``Y``, ``dY``, ``ddY`` (m+1, 6), allocation free
    (``R`` (4, 3, 3) and ``v`` (8, 3) scratch, :func:`motion_work`). Returns the first node (1..m)
    whose frame is at the Euler singularity (its rates set to zero), or -1."""
    m = G.shape[0]
    for a in range(6):
        Y[0, a] = Y0[a]
        dY[0, a] = dY0[a]
        ddY[0, a] = ddY0[a]
    A0, dA0, ddA0 = Y0[3:], dY0[3:], ddY0[3:]
    R0, Rg, Rj, Linv = R[0], R[1], R[2], R[3]
    wb, dwb, omega, alpha, d, Aj, t, u = v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]
    rotation_zyx_into(A0, R0)
    body_rates_into(A0, dA0, ddA0, wb, dwb)
    for a in range(3):
        omega[a] = R0[a, 0] * wb[0] + R0[a, 1] * wb[1] + R0[a, 2] * wb[2]
        alpha[a] = R0[a, 0] * dwb[0] + R0[a, 1] * dwb[1] + R0[a, 2] * dwb[2]
    bad = -1
    for j in range(m):
        rotation_zyx_into(G[j, 3:], Rg)
        for a in range(3):
            d[a] = R0[a, 0] * G[j, 0] + R0[a, 1] * G[j, 1] + R0[a, 2] * G[j, 2]
            for b in range(3):
                Rj[a, b] = R0[a, 0] * Rg[0, b] + R0[a, 1] * Rg[1, b] + R0[a, 2] * Rg[2, b]
        Aj[0] = math.atan2(Rj[1, 0], Rj[0, 0])
        Aj[1] = math.atan2(-Rj[2, 0], math.sqrt(Rj[2, 1] * Rj[2, 1] + Rj[2, 2] * Rj[2, 2]))
        Aj[2] = math.atan2(Rj[2, 1], Rj[2, 2])
        _cross_into(omega, d, t)      # omega x d
        _cross_into(omega, t, u)      # omega x (omega x d)
        for a in range(3):
            Y[j + 1, a] = Y0[a] + d[a]
            Y[j + 1, 3 + a] = Aj[a]
            dY[j + 1, a] = dY0[a] + t[a]
        _cross_into(alpha, d, t)      # alpha x d
        for a in range(3):
            ddY[j + 1, a] = ddY0[a] + (t[a] + u[a])
        if not body_rate_map_inverse(Aj, Linv):
            bad = j + 1
            for a in range(3):
                dY[j + 1, 3 + a] = 0.0
                ddY[j + 1, 3 + a] = 0.0
            continue
        # dA_j = L^-1 R_j^T omega;  ddA_j = L^-1 (R_j^T alpha - dL_j dA_j)
        for a in range(3):
            t[a] = Rj[0, a] * omega[0] + Rj[1, a] * omega[1] + Rj[2, a] * omega[2]
            u[a] = Rj[0, a] * alpha[0] + Rj[1, a] * alpha[1] + Rj[2, a] * alpha[2]
        for a in range(3):
            d[a] = Linv[a, 0] * t[0] + Linv[a, 1] * t[1] + Linv[a, 2] * t[2]  # dA_j (d no longer needed)
        cth, sth = math.cos(Aj[1]), math.sin(Aj[1])
        cph, sph = math.cos(Aj[2]), math.sin(Aj[2])
        dth, dph = d[1], d[2]
        u[0] -= (-cth * dth) * d[0]
        u[1] -= (cph * cth * dph - sph * sth * dth) * d[0] + (-sph * dph) * d[1]
        u[2] -= (-sph * cth * dph - cph * sth * dth) * d[0] + (-cph * dph) * d[1]
        for a in range(3):
            dY[j + 1, 3 + a] = d[a]
            ddY[j + 1, 3 + a] = Linv[a, 0] * u[0] + Linv[a, 1] * u[1] + Linv[a, 2] * u[2]
    return bad
