"""The numba frame kernels that the numba kernels of ``coopctrl/`` still call (``rotation_zyx_into``,
``body_rate_map_inverse``, ``rotation_vector_into`` and the others below), and the numba kernels of ``plants/``
kept for those callers (see :mod:`plants.cooperative._planar_kernel`).

Nothing of :mod:`plants` imports this module on import: :mod:`plants.frames` and
:mod:`plants.cooperative.loaded_state` hand these names out on first request (``from plants.frames import
rotation_zyx_into``), so that a caller compiled with numba keeps working. :mod:`plants.frames` itself calls the
compiled core (``plants._core``, plants/core/frames.h), which computes the same numbers. This module goes
when the last numba caller in ``coopctrl/`` does.
"""

from __future__ import annotations

import math

from numba import njit
from numba.extending import register_jitable

from plants.frames import EULER_SINGULARITY_COS

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
