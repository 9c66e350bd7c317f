"""Rotation charts: ZYX Euler angles taken about a constant rotation (docs/model.md s.2, rotation charts).

A spatial node's pose stays ``Y = (r, A)`` with ZYX Euler angles ``A = (psi, theta, phi)`` [rad],
but the angles are those of a chart ``C`` (a constant rotation):

.. math::
    R = C R(A), \\qquad \\omega = L(A) \\dot A

with ``omega`` the body angular velocity [rad/s]. ``C = I`` is the book's world chart. ``omega``,
the kinetic energy and ``W = blockdiag(m I, L^T I L)`` do not depend on ``C``; only world rotations
do. A chart is singular where its ``cos(theta) = 0``; :func:`recentre` moves it onto the current
rotation (``A = 0``, ``cos(theta) = 1``), keeping the rotation and ``omega``.
"""

from __future__ import annotations

import numpy as np

from plants.errors import EulerSingularityError, ParameterError
from plants.frames import (
    EULER_SINGULARITY_COS,
    body_rate_map,
    body_rate_map_dot,
    euler_zyx_from_rotation,
    rotation_zyx,
)

#: Tolerance [-] of ``|C^T C - I|`` and ``|det C - 1|`` for a chart given as a rotation matrix.
ROTATION_TOLERANCE = 1e-9


def chart_array(name: str, charts, count: int) -> np.ndarray:
    """``charts`` as a (count, 3, 3) float array of rotations; ``None`` gives identities.

    Raises :class:`ParameterError` naming ``name`` for another shape or a matrix that is not a
    rotation (orthonormal, det +1, to ``ROTATION_TOLERANCE``)."""
    if charts is None:
        return np.tile(np.eye(3), (count, 1, 1))
    try:
        C = np.array(charts, dtype=float)
    except (TypeError, ValueError):
        raise ParameterError(name, type(charts).__name__, f"{count} rotation matrices (3x3 each)") from None
    if C.shape != (count, 3, 3):
        raise ParameterError(name, C.shape, f"{count} rotation matrices, shape ({count}, 3, 3)")
    for k in range(count):
        Ck = C[k]
        if (not np.all(np.isfinite(Ck)) or np.max(np.abs(Ck.T @ Ck - np.eye(3))) > ROTATION_TOLERANCE
                or abs(np.linalg.det(Ck) - 1.0) > ROTATION_TOLERANCE):
            raise ParameterError(f"{name}[{k}]", Ck.tolist(), "a rotation matrix (orthonormal, det +1)")
    return C


def is_identity(C) -> bool:
    """True for the book's world chart (exactly the identity)."""
    return bool(np.array_equal(np.asarray(C, dtype=float), np.eye(3)))


def recentre(C, A, dA):
    """The chart centred on the current rotation: ``(C', A' = 0, dA')`` with ``C' = C R(A)`` and
    ``dA' = L(0)^-1 L(A) dA`` (the same body angular velocity; ``L(0)`` is a permutation)."""
    A = np.asarray(A, dtype=float)
    Cn = np.asarray(C, dtype=float) @ rotation_zyx(A)
    # re-orthonormalize (the product of many charts drifts by rounding); polar factor by SVD
    U, _, Vt = np.linalg.svd(Cn)
    Cn = U @ Vt
    omega = body_rate_map(A) @ np.asarray(dA, dtype=float)
    return Cn, np.zeros(3), np.linalg.solve(body_rate_map(np.zeros(3)), omega)


def world_coordinates(C, A, dA, ddA, where: str = "node"):
    """``(A_w, dA_w, ddA_w)``: a node's angles, rates and accelerations in the book's world chart.

    .. math::
        R(A_w) = C R(A), \\quad \\omega = L(A) \\dot A = L(A_w) \\dot A_w, \\quad
        \\dot\\omega = L(A) \\ddot A + \\dot L(A, \\dot A) \\dot A
        = L(A_w) \\ddot A_w + \\dot L(A_w, \\dot A_w) \\dot A_w

    The identity chart returns its arguments (the book's coordinates themselves). Raises
    :class:`EulerSingularityError` where the world angles do not exist (``|cos theta_w|`` below
    ``EULER_SINGULARITY_COS``)."""
    A, dA, ddA = (np.asarray(a, dtype=float) for a in (A, dA, ddA))
    if is_identity(C):
        return A.copy(), dA.copy(), ddA.copy()
    Aw = euler_zyx_from_rotation(np.ascontiguousarray(np.asarray(C, dtype=float) @ rotation_zyx(A)))
    c = float(np.cos(Aw[1]))
    if abs(c) < EULER_SINGULARITY_COS:
        raise EulerSingularityError(f"{where} (its book coordinates: world ZYX Euler angles)", float(Aw[1]), c)
    omega = body_rate_map(A) @ dA
    domega = body_rate_map(A) @ ddA + body_rate_map_dot(A, dA) @ dA
    Lw = body_rate_map(Aw)
    dAw = np.linalg.solve(Lw, omega)
    ddAw = np.linalg.solve(Lw, domega - body_rate_map_dot(Aw, dAw) @ dAw)
    return Aw, dAw, ddAw
