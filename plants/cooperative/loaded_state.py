"""Nominal motion of the loaded state (148): contact nodes carried rigidly by the object.

If the object moves rigidly, node j follows ``r_j = r_0 + R(A_0) rho_0j`` and its frame
``R_j = R(A_0) R(A_0j)``. The book writes the orientation as ``A_j = A_0 + A_0j``, which is
exact only when the rotations commute; we compose rotations and extract the ZYX angles.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.frames import (
    body_rate_map,
    body_rate_map_dot,
    body_rate_map_inverse,
    check_euler,
    euler_zyx_from_rotation,
    rotation_zyx,
)


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
    if space == "planar":
        return _planar_motion(Y0, dY0, ddY0, G)
    Y, dY, ddY, bad = _spatial_motion(Y0, dY0, ddY0, G)
    if bad >= 0:
        check_euler(Y[bad, 3:], f"nominal pose of contact node {bad}")
    return Y, dY, ddY


@njit(cache=True)
def _planar_motion(Y0, dY0, ddY0, G):
    m = G.shape[0]
    Y = np.empty((m + 1, 3))
    dY = np.empty((m + 1, 3))
    ddY = np.empty((m + 1, 3))
    Y[0], dY[0], ddY[0] = Y0, dY0, ddY0
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
    return Y, dY, ddY


@njit(cache=True)
def _cross(a, b):
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@njit(cache=True)
def _spatial_motion(Y0, dY0, ddY0, G):
    m = G.shape[0]
    Y = np.empty((m + 1, 6))
    dY = np.empty((m + 1, 6))
    ddY = np.empty((m + 1, 6))
    Y[0], dY[0], ddY[0] = Y0, dY0, ddY0
    A0, dA0, ddA0 = Y0[3:], dY0[3:], ddY0[3:]
    R0 = rotation_zyx(A0)
    L0 = body_rate_map(A0)
    omega = R0 @ (L0 @ dA0)
    alpha = R0 @ (L0 @ ddA0 + body_rate_map_dot(A0, dA0) @ dA0)
    Linv = np.empty((3, 3))
    bad = -1
    for j in range(m):
        d = R0 @ G[j, :3]
        Rj = R0 @ rotation_zyx(G[j, 3:])
        Aj = euler_zyx_from_rotation(Rj)
        wxd = _cross(omega, d)
        acc = _cross(alpha, d) + _cross(omega, wxd)
        for a in range(3):
            Y[j + 1, a] = Y0[a] + d[a]
            Y[j + 1, 3 + a] = Aj[a]
            dY[j + 1, a] = dY0[a] + wxd[a]
            ddY[j + 1, a] = ddY0[a] + acc[a]
        if not body_rate_map_inverse(Aj, Linv):
            bad = j + 1
            dY[j + 1, 3:] = 0.0
            ddY[j + 1, 3:] = 0.0
            continue
        dAj = Linv @ (Rj.T @ omega)
        ddAj = Linv @ (Rj.T @ alpha - body_rate_map_dot(Aj, dAj) @ dAj)
        dY[j + 1, 3:] = dAj
        ddY[j + 1, 3:] = ddAj
    return Y, dY, ddY, bad
