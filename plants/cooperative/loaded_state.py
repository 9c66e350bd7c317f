"""Nominal motion of the loaded state (148): contact nodes carried rigidly by the object.

If the object moves rigidly, node j follows ``r_j = r_0 + R(A_0) rho_0j`` and its frame
``R_j = R(A_0) R(A_0j)``. The book writes the orientation as ``A_j = A_0 + A_0j``, which is
exact only when the rotations commute; we compose rotations and extract the ZYX angles.
"""

from __future__ import annotations

import numpy as np

from plants.frames import (
    body_rate_map,
    body_rate_map_dot,
    body_rate_map_inv,
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
    ``ddA_j = L(A_j)^-1 (R_j^T alpha - dL_j dA_j)``.
    """
    Y0 = np.asarray(Y0, dtype=float)
    dY0 = np.asarray(dY0, dtype=float)
    ddY0 = np.asarray(ddY0, dtype=float)
    G = np.atleast_2d(np.asarray(grasps, dtype=float))
    m = G.shape[0]
    p = Y0.size
    Y = np.empty((m + 1, p))
    dY = np.empty((m + 1, p))
    ddY = np.empty((m + 1, p))
    Y[0], dY[0], ddY[0] = Y0, dY0, ddY0
    if space == "planar":
        th, w, al = Y0[2], dY0[2], ddY0[2]
        c, s = np.cos(th), np.sin(th)
        for j in range(m):
            d = np.array([c * G[j, 0] - s * G[j, 1], s * G[j, 0] + c * G[j, 1]])
            perp = np.array([-d[1], d[0]])  # omega x d in the plane
            Y[j + 1, :2] = Y0[:2] + d
            Y[j + 1, 2] = th + G[j, 2]
            dY[j + 1, :2] = dY0[:2] + w * perp
            dY[j + 1, 2] = w
            ddY[j + 1, :2] = ddY0[:2] + al * perp - w * w * d
            ddY[j + 1, 2] = al
        return Y, dY, ddY
    A0, dA0, ddA0 = Y0[3:], dY0[3:], ddY0[3:]
    R0 = rotation_zyx(A0)
    L0 = body_rate_map(A0)
    omega = R0 @ (L0 @ dA0)
    alpha = R0 @ (L0 @ ddA0 + body_rate_map_dot(A0, dA0) @ dA0)
    for j in range(m):
        d = R0 @ G[j, :3]
        Rj = R0 @ rotation_zyx(G[j, 3:])
        Aj = euler_zyx_from_rotation(Rj)
        Linv = body_rate_map_inv(Aj, f"nominal pose of contact node {j + 1}")
        dAj = Linv @ (Rj.T @ omega)
        ddAj = Linv @ (Rj.T @ alpha - body_rate_map_dot(Aj, dAj) @ dAj)
        wxd = np.cross(omega, d)
        Y[j + 1] = np.r_[Y0[:3] + d, Aj]
        dY[j + 1] = np.r_[dY0[:3] + wxd, dAj]
        ddY[j + 1] = np.r_[ddY0[:3] + np.cross(alpha, d) + np.cross(omega, wxd), ddAj]
    return Y, dY, ddY
