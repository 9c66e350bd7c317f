"""The numba kernels of :mod:`plants.frames`' functions that return new arrays (``rotation_zyx``,
``rotation_zyx_partials``, ``euler_zyx_from_rotation``, ``body_rate_map``, ``body_rate_map_dot``,
``rotation_planar``): the references that tests/test_core_frames.py holds the compiled core to, bit for bit.
:mod:`plants.frames` itself calls the compiled core; nothing in a run calls these."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.frames import rotation_zyx_into, rotation_zyx_partials_into


@njit(cache=True)
def rotation_zyx(A):
    """``R(A) = Rz(psi) Ry(theta) Rx(phi)`` for ``A = (psi, theta, phi)`` [rad]; 3x3 (a new array)."""
    R = np.empty((3, 3))
    rotation_zyx_into(A, R)
    return R


@njit(cache=True)
def rotation_zyx_partials(A):
    """``(dR/dpsi, dR/dtheta, dR/dphi)`` of :func:`rotation_zyx`, each 3x3 (exact; new arrays)."""
    dpsi = np.empty((3, 3))
    dth = np.empty((3, 3))
    dph = np.empty((3, 3))
    rotation_zyx_partials_into(A, dpsi, dth, dph)
    return dpsi, dth, dph


@njit(cache=True)
def euler_zyx_from_rotation(R):
    """ZYX Euler angles ``A = (psi, theta, phi)`` [rad] of a rotation matrix, theta in [-pi/2, pi/2]."""
    A = np.empty(3)
    A[0] = math.atan2(R[1, 0], R[0, 0])
    A[1] = math.atan2(-R[2, 0], math.sqrt(R[2, 1] * R[2, 1] + R[2, 2] * R[2, 2]))
    A[2] = math.atan2(R[2, 1], R[2, 2])
    return A


@njit(cache=True)
def body_rate_map(A):
    """``L(A)`` with ``omega_body = L(A) dA/dt`` (105); 3x3, defined everywhere."""
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    L = np.zeros((3, 3))
    L[0, 0] = -sth
    L[0, 2] = 1.0
    L[1, 0] = sph * cth
    L[1, 1] = cph
    L[2, 0] = cph * cth
    L[2, 1] = -sph
    return L


@njit(cache=True)
def body_rate_map_dot(A, dA):
    """``dL/dt`` for Euler rates ``dA`` [rad/s]; 3x3."""
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    dth, dph = dA[1], dA[2]
    Ld = np.zeros((3, 3))
    Ld[0, 0] = -cth * dth
    Ld[1, 0] = cph * cth * dph - sph * sth * dth
    Ld[1, 1] = -sph * dph
    Ld[2, 0] = -sph * cth * dph - cph * sth * dth
    Ld[2, 1] = -cph * dph
    return Ld


@njit(cache=True)
def rotation_planar(theta):
    """2x2 rotation in the (x, z) plane, ``theta`` [rad] from +x towards +z."""
    c, s = math.cos(theta), math.sin(theta)
    R = np.empty((2, 2))
    R[0, 0] = c
    R[0, 1] = -s
    R[1, 0] = s
    R[1, 1] = c
    return R
