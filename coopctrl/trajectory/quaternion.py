"""Unit quaternions ``q = (w, x, y, z)`` (scalar first) and the rotation group maps the trajectories use.

Every function works on stacks: a quaternion argument has shape ``(..., 4)``, a vector ``(..., 3)``.
Conventions (docs/model.md s.2): ``R(A) = Rz(psi) Ry(theta) Rx(phi)`` for ZYX Euler angles
``A = (psi, theta, phi)`` [rad]; ``q`` rotates body vectors into the world, ``v_w = R(q) v_b``; the
rotation vector ``phi`` [rad] of ``R`` is its axis times its angle, ``R = exp([phi]_x)``.

.. math::

    \\exp(\\phi) = (\\cos(|\\phi|/2),\\ \\sin(|\\phi|/2)\\, \\phi / |\\phi|), \\qquad
    \\log(q) = 2\\, \\operatorname{atan2}(|v|, w)\\, v / |v|,\\quad q = (w, v)

``log`` uses ``atan2`` (accurate at every angle, also near 0 and pi) and returns an angle in
``[0, 2 pi)``: callers pick the short way by flipping ``q`` to ``w >= 0`` first (:func:`shortest`).
"""

from __future__ import annotations

import numpy as np

#: ``|w|`` [-] below which a relative rotation counts as a half turn (angle ``pi - 2 |w|`` rad): its two
#: geodesics then differ in length by at most ``4e-12`` rad and :func:`shortest` picks one by the axis.
HALF_TURN_W = 1e-12


def multiply(a, b) -> np.ndarray:
    """Hamilton product ``a b`` (the rotation ``R(a) R(b)``)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack((aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw), axis=-1)


def conjugate(q) -> np.ndarray:
    """``(w, -x, -y, -z)``: the inverse rotation of a unit quaternion."""
    q = np.array(q, dtype=float)
    q[..., 1:] *= -1.0
    return q


def exp(phi) -> np.ndarray:
    """The unit quaternion of the rotation vector ``phi`` [rad] (``sinc`` keeps ``phi -> 0`` exact)."""
    phi = np.asarray(phi, dtype=float)
    angle = np.linalg.norm(phi, axis=-1)
    half_sinc = 0.5 * np.sinc(angle / (2.0 * np.pi))  # sin(angle / 2) / angle
    return np.concatenate((np.cos(0.5 * angle)[..., None], half_sinc[..., None] * phi), axis=-1)


def log(q) -> np.ndarray:
    """The rotation vector [rad] of the unit quaternion ``q``: ``2 atan2(|v|, w) v / |v|`` (``0`` at ``v = 0``)."""
    q = np.asarray(q, dtype=float)
    n = np.linalg.norm(q[..., 1:], axis=-1)
    safe = np.where(n > 0.0, n, 1.0)
    factor = np.where(n > 0.0, 2.0 * np.arctan2(n, q[..., 0]) / safe, 2.0 / np.where(q[..., 0] != 0.0, q[..., 0], 1.0))
    return factor[..., None] * q[..., 1:]


def shortest(q) -> np.ndarray:
    """``q`` or ``-q`` (the same rotation), the one whose :func:`log` is the shorter rotation: ``w > 0``.

    Within :data:`HALF_TURN_W` of a half turn both are as short; then the sign making the largest
    component of the axis positive is taken, so that the rounding of the input does not choose the way.
    """
    q = np.array(q, dtype=float)
    v = q[..., 1:]
    lead = np.take_along_axis(v, np.argmax(np.abs(v), axis=-1)[..., None], axis=-1)[..., 0]
    flip = np.where(np.abs(q[..., 0]) <= HALF_TURN_W, lead < 0.0, q[..., 0] < 0.0)
    q[flip] *= -1.0
    return q


def rotate(q, v) -> np.ndarray:
    """``R(q) v``: the body vector ``v`` in world axes."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    w, u = q[..., :1], q[..., 1:]
    t = 2.0 * np.cross(u, v)
    return v + w * t + np.cross(u, t)


def matrix(q) -> np.ndarray:
    """The rotation matrix ``R(q)``, shape ``(..., 3, 3)``."""
    w, x, y, z = np.moveaxis(np.asarray(q, dtype=float), -1, 0)
    return np.stack((
        np.stack((1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)), axis=-1),
        np.stack((2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)), axis=-1),
        np.stack((2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)), axis=-1),
    ), axis=-2)


def from_zyx(A) -> np.ndarray:
    """The unit quaternion of ZYX Euler angles ``A = (psi, theta, phi)`` [rad]: ``q_z(psi) q_y(theta) q_x(phi)``."""
    A = np.asarray(A, dtype=float)
    cp, sp = np.cos(0.5 * A[..., 0]), np.sin(0.5 * A[..., 0])
    ct, st = np.cos(0.5 * A[..., 1]), np.sin(0.5 * A[..., 1])
    cf, sf = np.cos(0.5 * A[..., 2]), np.sin(0.5 * A[..., 2])
    return np.stack((cp * ct * cf + sp * st * sf,
                     cp * ct * sf - sp * st * cf,
                     cp * st * cf + sp * ct * sf,
                     sp * ct * cf - cp * st * sf), axis=-1)


def to_zyx(q) -> tuple[np.ndarray, np.ndarray]:
    """The principal ZYX Euler angles of ``q`` (``theta`` in ``[-pi/2, pi/2]``, as
    ``plants.frames.euler_zyx_from_rotation``) and ``|cos(theta)| = sqrt(R_21^2 + R_22^2)`` [-]."""
    R = matrix(q)
    cos_theta = np.hypot(R[..., 2, 1], R[..., 2, 2])
    A = np.stack((np.arctan2(R[..., 1, 0], R[..., 0, 0]), np.arctan2(-R[..., 2, 0], cos_theta),
                  np.arctan2(R[..., 2, 1], R[..., 2, 2])), axis=-1)
    return A, cos_theta


def nearest_zyx(A, ref) -> np.ndarray:
    """The ZYX angles of the same rotation as the principal angles ``A`` closest to ``ref`` [rad].

    A rotation has two families of ZYX angles away from ``cos(theta) = 0``: ``(psi, theta, phi)`` and
    ``(psi + pi, pi - theta, phi + pi)``, each up to ``2 pi`` in every angle. Each family is shifted by
    whole turns to ``ref``; the closer family (Euclidean) is returned.
    """
    A, ref = np.asarray(A, dtype=float), np.asarray(ref, dtype=float)
    B = A + np.array([np.pi, 0.0, np.pi])
    B[..., 1] = np.pi - A[..., 1]
    turn = 2.0 * np.pi
    A = A + turn * np.round((ref - A) / turn)
    B = B + turn * np.round((ref - B) / turn)
    use_b = np.sum((B - ref) ** 2, axis=-1) < np.sum((A - ref) ** 2, axis=-1)
    return np.where(use_b[..., None], B, A)
