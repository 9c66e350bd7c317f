"""Nominal motion of the loaded state (148): contact nodes carried rigidly by the object.

If the object moves rigidly, node j follows ``r_j = r_0 + R(A_0) rho_0j`` and its frame
``R_j = R(A_0) R(A_0j)``. The book writes the orientation as ``A_j = A_0 + A_0j``, which is
exact only when the rotations commute; we compose rotations and extract the ZYX angles.
"""

from __future__ import annotations

import numpy as np

from plants import _core
from plants.frames import check_euler


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
    p = 3 if space == "planar" else 6
    Y, dY, ddY = (np.empty((G.shape[0] + 1, p)) for _ in range(3))
    bad = _core.nominal_node_motion(Y0, dY0, ddY0, G, Y, dY, ddY)  # plants/core/rigid_motion.h
    if bad >= 0:
        check_euler(Y[bad, 3:], f"nominal pose of contact node {bad}")
    return Y, dY, ddY

