"""Frames: ZYX Euler angles, the body-rate map ``L(A)`` and its time derivative (docs/model.md s.2).

Convention (ours, docs/model.md s.2): a node pose is ``Y = (r, A)`` with ``r`` in [m] and
``A = (psi, theta, phi)`` in [rad], and

.. math::

    R(A) = R_z(\\psi) R_y(\\theta) R_x(\\phi), \\qquad
    \\omega = L(A) \\dot A, \\qquad
    L(A) = \\begin{bmatrix} -s_\\theta & 0 & 1 \\\\
                           s_\\phi c_\\theta & c_\\phi & 0 \\\\
                           c_\\phi c_\\theta & -s_\\phi & 0 \\end{bmatrix}

where ``omega`` is the **body** angular velocity [rad/s] (expressed in the node's principal
axes), as in the kinetic energy (104-105). ``L`` is singular at ``cos(theta) = 0``; every
function that divides by ``cos(theta)`` checks :data:`EULER_SINGULARITY_COS` first and the
kernels return a status instead of dividing through it.

Planar reduction: ``Y = (x, z, theta)``, rotation in the vertical x-z plane with ``theta``
measured from +x towards +z, ``L = 1``.

Every function here calls the compiled core (``plants._core``, plants/core/frames.h) or is plain Python.
"""

from __future__ import annotations

import math

import numpy as np

from plants import _core
from plants.errors import EulerSingularityError

#: Smallest ``|cos(theta)|`` [-] at which ``L(A)^-1`` is still evaluated. Below it the pose
#: is reported as an Euler-angle singularity (theta within ~1e-6 rad of +-pi/2).
EULER_SINGULARITY_COS = 1e-6


def rotation_zyx(A) -> np.ndarray:
    """``R(A) = Rz(psi) Ry(theta) Rx(phi)`` for ``A = (psi, theta, phi)`` [rad]; 3x3 (a new array)."""
    R = np.empty((3, 3))
    _core.rotation_zyx_into(_angles(A), R)
    return R


def rotation_zyx_partials(A) -> tuple:
    """``(dR/dpsi, dR/dtheta, dR/dphi)`` of :func:`rotation_zyx`, each 3x3 (exact; new arrays)."""
    dpsi, dth, dph = np.empty((3, 3)), np.empty((3, 3)), np.empty((3, 3))
    _core.rotation_zyx_partials_into(_angles(A), dpsi, dth, dph)
    return dpsi, dth, dph


def euler_zyx_from_rotation(R) -> np.ndarray:
    """ZYX Euler angles ``A = (psi, theta, phi)`` [rad] of a rotation matrix, theta in [-pi/2, pi/2]."""
    A = np.empty(3)
    _core.euler_zyx_from_rotation_into(np.ascontiguousarray(R, dtype=float), A)
    return A


def body_rate_map(A) -> np.ndarray:
    """``L(A)`` with ``omega_body = L(A) dA/dt`` (105); 3x3, defined everywhere."""
    L = np.empty((3, 3))
    _core.body_rate_map_into(_angles(A), L)
    return L


def body_rate_map_dot(A, dA) -> np.ndarray:
    """``dL/dt`` for Euler rates ``dA`` [rad/s]; 3x3."""
    Ld = np.empty((3, 3))
    _core.body_rate_map_dot_into(_angles(A), _angles(dA), Ld)
    return Ld


def rotation_planar(theta) -> np.ndarray:
    """2x2 rotation in the (x, z) plane, ``theta`` [rad] from +x towards +z."""
    R = np.empty((2, 2))
    _core.rotation_planar_into(float(theta), R)
    return R


def check_euler(A, where: str = "pose") -> None:
    """Raise :class:`EulerSingularityError` if ``A`` is within the singular band of ``L``."""
    theta = float(A[1])
    c = math.cos(theta)
    if abs(c) < EULER_SINGULARITY_COS:
        raise EulerSingularityError(where, theta, c)


def body_rate_map_inv(A, where: str = "pose") -> np.ndarray:
    """``L(A)^-1`` as a new array; raises :class:`EulerSingularityError` near ``cos(theta) = 0``."""
    Linv = np.empty((3, 3))
    if not _core.body_rate_map_inverse_into(_angles(A), Linv):
        check_euler(A, where)
    return Linv


def _angles(A) -> np.ndarray:
    """``A`` as the compiled core takes it: float64, C-contiguous (a view when it already is)."""
    return np.ascontiguousarray(A, dtype=float)


def rotation_vector(M) -> np.ndarray:
    """Rotation vector [rad] (3,) of the rotation matrix ``M`` (3x3): ``theta`` times the unit axis, ``theta`` in
    [0, pi], from the unit quaternion of ``M`` (plants/core/frames.h: ``rotation_vector_into``)."""
    out = np.empty(3)
    _core.rotation_vector_into(np.ascontiguousarray(M, dtype=float), out)
    return out

