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

The functions that return new arrays (:func:`rotation_zyx`, :func:`rotation_zyx_partials`,
:func:`euler_zyx_from_rotation`, :func:`body_rate_map`, :func:`body_rate_map_dot`, :func:`rotation_planar`,
:func:`body_rate_map_inv`) call the compiled core (``plants._core``, plants/core/frames.h). The ``*_into``
functions and :func:`body_rate_map_inverse` are ``numba.njit`` kernels that other numba kernels call. :func:`rotation_vector_into` is a plain
Python function that a jitted caller compiles (``register_jitable``): the inverse kinematics call
it from Python too, without loading a compiled function or scipy.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numba.extending import register_jitable

from plants import _core
from plants.errors import EulerSingularityError

#: Smallest ``|cos(theta)|`` [-] at which ``L(A)^-1`` is still evaluated. Below it the pose
#: is reported as an Euler-angle singularity (theta within ~1e-6 rad of +-pi/2).
EULER_SINGULARITY_COS = 1e-6


@njit(cache=True, _nrt=False)
def rotation_zyx_into(A, R):
    """Write ``R(A) = Rz(psi) Ry(theta) Rx(phi)`` for ``A = (psi, theta, phi)`` [rad] into ``R`` (3x3)."""
    cps, sps = math.cos(A[0]), math.sin(A[0])
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    R[0, 0] = cps * cth
    R[0, 1] = cps * sth * sph - sps * cph
    R[0, 2] = cps * sth * cph + sps * sph
    R[1, 0] = sps * cth
    R[1, 1] = sps * sth * sph + cps * cph
    R[1, 2] = sps * sth * cph - cps * sph
    R[2, 0] = -sth
    R[2, 1] = cth * sph
    R[2, 2] = cth * cph


def rotation_zyx(A) -> np.ndarray:
    """``R(A) = Rz(psi) Ry(theta) Rx(phi)`` for ``A = (psi, theta, phi)`` [rad]; 3x3 (a new array)."""
    R = np.empty((3, 3))
    _core.rotation_zyx_into(_angles(A), R)
    return R


@njit(cache=True, _nrt=False)
def rotation_zyx_partials_into(A, dpsi, dth, dph):
    """Write ``(dR/dpsi, dR/dtheta, dR/dphi)`` of :func:`rotation_zyx` (exact) into three 3x3 arrays."""
    _partials_from_trig(math.cos(A[0]), math.sin(A[0]), math.cos(A[1]), math.sin(A[1]),
                        math.cos(A[2]), math.sin(A[2]), dpsi, dth, dph)


@njit(cache=True, _nrt=False)
def rotation_zyx_and_partials_into(A, R, dR):
    """:func:`rotation_zyx_into` and :func:`rotation_zyx_partials_into` (into ``dR[0..2]``) with one
    evaluation of the six sines and cosines."""
    rotation_and_partials_from_trig(math.cos(A[0]), math.sin(A[0]), math.cos(A[1]), math.sin(A[1]),
                                    math.cos(A[2]), math.sin(A[2]), R, dR[0], dR[1], dR[2])


@njit(cache=True, inline="always")
def rotation_and_partials_from_trig(cps, sps, cth, sth, cph, sph, R, dpsi, dth, dph):
    """``R(A)`` and its three partials (as :func:`rotation_zyx_and_partials_into`) from the cosines
    and sines of ``A = (psi, theta, phi)``."""
    R[0, 0] = cps * cth
    R[0, 1] = cps * sth * sph - sps * cph
    R[0, 2] = cps * sth * cph + sps * sph
    R[1, 0] = sps * cth
    R[1, 1] = sps * sth * sph + cps * cph
    R[1, 2] = sps * sth * cph - cps * sph
    R[2, 0] = -sth
    R[2, 1] = cth * sph
    R[2, 2] = cth * cph
    _partials_from_trig(cps, sps, cth, sth, cph, sph, dpsi, dth, dph)


@njit(cache=True, inline="always")
def _partials_from_trig(cps, sps, cth, sth, cph, sph, dpsi, dth, dph):
    """The three partials of ``R(A)`` from the cosines and sines of ``A``."""
    dpsi[0, 0] = -sps * cth
    dpsi[0, 1] = -sps * sth * sph - cps * cph
    dpsi[0, 2] = -sps * sth * cph + cps * sph
    dpsi[1, 0] = cps * cth
    dpsi[1, 1] = cps * sth * sph - sps * cph
    dpsi[1, 2] = cps * sth * cph + sps * sph
    dpsi[2, 0] = 0.0
    dpsi[2, 1] = 0.0
    dpsi[2, 2] = 0.0
    dth[0, 0] = -cps * sth
    dth[0, 1] = cps * cth * sph
    dth[0, 2] = cps * cth * cph
    dth[1, 0] = -sps * sth
    dth[1, 1] = sps * cth * sph
    dth[1, 2] = sps * cth * cph
    dth[2, 0] = -cth
    dth[2, 1] = -sth * sph
    dth[2, 2] = -sth * cph
    dph[0, 0] = 0.0
    dph[1, 0] = 0.0
    dph[2, 0] = 0.0
    dph[0, 1] = cps * sth * cph + sps * sph
    dph[0, 2] = -cps * sth * sph + sps * cph
    dph[1, 1] = sps * sth * cph - cps * sph
    dph[1, 2] = -sps * sth * sph - cps * cph
    dph[2, 1] = cth * cph
    dph[2, 2] = -cth * sph


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


@register_jitable
def rotation_vector_into(M, out):
    """Rotation vector [rad] of the rotation matrix ``M`` (3x3) into ``out`` (3,): the unit quaternion
    ``(w, v)`` of ``M`` (Shepperd's choice of the largest of ``trace, M_00, M_11, M_22``), sign chosen
    with ``w >= 0``, then

    .. math::

        \\theta = 2 \\operatorname{atan2}(|v|, w), \\qquad
        out = \\frac{\\theta}{\\sin(\\theta / 2)} v

    with ``theta / sin(theta / 2) = 2 + theta^2 / 12 + 7 theta^4 / 2880`` for ``theta <= 1e-3``. The
    inverse kinematics' rotation error (``M = R_target R(q)^T``), in Python and compiled alike
    (``register_jitable``: a plain Python function, compiled into a jitted caller)."""
    tr = M[0, 0] + M[1, 1] + M[2, 2]
    if tr >= M[0, 0] and tr >= M[1, 1] and tr >= M[2, 2]:
        w = 1.0 + tr
        x = M[2, 1] - M[1, 2]
        y = M[0, 2] - M[2, 0]
        z = M[1, 0] - M[0, 1]
    elif M[0, 0] >= M[1, 1] and M[0, 0] >= M[2, 2]:
        x = 1.0 + 2.0 * M[0, 0] - tr
        y = M[0, 1] + M[1, 0]
        z = M[0, 2] + M[2, 0]
        w = M[2, 1] - M[1, 2]
    elif M[1, 1] >= M[2, 2]:
        x = M[0, 1] + M[1, 0]
        y = 1.0 + 2.0 * M[1, 1] - tr
        z = M[1, 2] + M[2, 1]
        w = M[0, 2] - M[2, 0]
    else:
        x = M[0, 2] + M[2, 0]
        y = M[1, 2] + M[2, 1]
        z = 1.0 + 2.0 * M[2, 2] - tr
        w = M[1, 0] - M[0, 1]
    norm = math.sqrt(w * w + x * x + y * y + z * z)
    if w < 0.0:
        norm = -norm
    w, x, y, z = w / norm, x / norm, y / norm, z / norm
    s = math.sqrt(x * x + y * y + z * z)
    theta = 2.0 * math.atan2(s, w)
    if theta <= 1e-3:  # theta / sin(theta / 2) by its series
        t2 = theta * theta
        scale = 2.0 + t2 / 12.0 + 7.0 * t2 * t2 / 2880.0
    else:
        scale = theta / math.sin(0.5 * theta)
    out[0] = scale * x
    out[1] = scale * y
    out[2] = scale * z


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


@njit(cache=True, _nrt=False)
def body_rate_map_inverse(A, Linv):
    """Write ``L(A)^-1`` into ``Linv`` (3x3); return False (and leave it) at a singularity.

    .. math::
        L^{-1} = \\begin{bmatrix} 0 & s_\\phi / c_\\theta & c_\\phi / c_\\theta \\\\
                                0 & c_\\phi & -s_\\phi \\\\
                                1 & s_\\phi t_\\theta & c_\\phi t_\\theta \\end{bmatrix}
    """
    cth, sth = math.cos(A[1]), math.sin(A[1])
    if abs(cth) < EULER_SINGULARITY_COS:
        return False
    cph, sph = math.cos(A[2]), math.sin(A[2])
    tth = sth / cth
    Linv[0, 0] = 0.0
    Linv[0, 1] = sph / cth
    Linv[0, 2] = cph / cth
    Linv[1, 0] = 0.0
    Linv[1, 1] = cph
    Linv[1, 2] = -sph
    Linv[2, 0] = 1.0
    Linv[2, 1] = sph * tth
    Linv[2, 2] = cph * tth
    return True


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
