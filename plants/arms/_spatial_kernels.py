"""Numba kernels of a spatial serial arm with revolute standard-DH joints (docs/model.md s.4).

Kept for the numba code that still calls it: pre-flight's inverse kinematics (coopctrl/analysis/preflight_ik.py);
SerialArm calls the compiled core (plants/core/dh_arm.h). It goes with its last caller
(tests/test_plants_without_numba.py lists it).

The hot path of the cooperative right-hand side: :func:`spatial_arm_terms` evaluates, in one
pass over the chain, everything (166)-(172) need for arm i:

.. math::

    H(q)\\ddot q + h(q, \\dot q) = \\tau, \\qquad Y = \\Phi(q), \\qquad
    \\dot Y = J \\dot q, \\qquad \\ddot Y = J \\ddot q + \\dot J \\dot q

Algorithm (all quantities in world coordinates):

* forward kinematics, and the recursive Newton-Euler forward pass with ``qdd = 0`` and the
  base accelerating with ``-g`` (so gravity is in ``h``); the backward pass gives ``h``;
* the composite-rigid-body algorithm for ``H``, composites kept about the joint axis point
  with their first moment (no division by a composite mass, links may be massless);
* the geometric Jacobian from the joint axes, mapped to ZYX Euler rates by
  ``dA = L(A)^-1 R^T omega_world``;
* ``Jdq`` from the tip acceleration of the ``qdd = 0`` pass, with gravity removed:
  ``ddA = L^-1 (R^T alpha_world - dL/dt dA)``.

DH table layout (one row per joint, float64 ``(n, 16)``, standard DH as Corke's toolbox)::

    [a, alpha, d, offset, mass, rcx, rcy, rcz, Ixx, Iyy, Izz, Ixy, Iyz, Ixz, motor_inertia, viscous]

with ``a, d`` [m], ``alpha, offset`` [rad], ``mass`` [kg], the COM ``rc`` [m] and the inertia
about the COM [kg m^2] in the link frame, ``motor_inertia`` [kg m^2] added to ``H``'s diagonal,
``viscous`` [N m s/rad] adding ``viscous * dq`` to ``h``.

No Python objects, no numpy linear algebra: loops are written out. The only allocation is one
small work array per call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.arms._chain_kernels import tip_pose
from plants.frames import EULER_SINGULARITY_COS

# Columns of the DH table.
COL_A, COL_ALPHA, COL_D, COL_OFFSET, COL_MASS = 0, 1, 2, 3, 4
COL_RC = 5  # 5, 6, 7
COL_I = 8  # Ixx, Iyy, Izz, Ixy, Iyz, Ixz
COL_MOTOR, COL_VISCOUS = 14, 15
DH_COLUMNS = 16

# Work-array layout, one row per frame k = 0..n (frame 0 = base).
_R = 0  # 9: world rotation of frame k (row-major)
_O = 9  # 3: world origin of frame k
_W = 12  # 3: angular velocity of body k
_AL = 15  # 3: angular acceleration of body k (qdd = 0)
_AC = 18  # 3: linear acceleration of o_k as a point of body k (incl. -g)
_C = 21  # 3: COM of link k (world)
_IW = 24  # 6: world inertia of link k about its COM: xx, yy, zz, xy, yz, xz
_F = 30  # 3: inertial force of link k
_N = 33  # 3: inertial moment of link k about its COM
_WORK = 36
# tip_pose (plants.arms._chain_kernels) reads a frame row's rotation at _R and its origin at _O: the same columns
# as the chain kernel's rows
assert _R == 0 and _O == 9


@njit(cache=True)
def spatial_arm_terms(q, dq, dh, base, tool, gravity, H, h, Y, J, Jdq):
    """Fill ``H`` (n x n), ``h`` (n), ``Y`` (6), ``J`` (6 x n) and ``Jdq`` (6) in place.

    Args:
        q: Joint angles [rad], (n,).
        dq: Joint rates [rad/s], (n,).
        dh: DH table, (n, 16), see the module docstring.
        base: World pose of the arm base, 4x4 [m].
        tool: Transform from the last DH frame to the node frame, 4x4 [m].
        gravity: Gravity acceleration [m/s^2], (3,), e.g. (0, 0, -9.81).
        H: Out: joint-space inertia [kg m^2].
        h: Out: Coriolis, centrifugal, gravity and viscous torques [N m].
        Y: Out: node pose (position [m], ZYX Euler angles [rad]).
        J: Out: analytic Jacobian, rows 0-2 [m/rad], rows 3-5 Euler rates per joint rate.
        Jdq: Out: ``dJ/dt dq`` [m/s^2, rad/s^2].

    Returns:
        0 on success; 1 if the tip's Euler angles are at the singularity of ``L`` (then the
        angular rows of ``J`` and ``Jdq`` are set to zero, everything else is valid).
    """
    n = q.shape[0]
    wk = np.empty((n + 1, _WORK))
    gx, gy, gz = gravity[0], gravity[1], gravity[2]
    b = wk[0]
    for i in range(3):
        for j in range(3):
            b[_R + 3 * i + j] = base[i, j]
        b[_O + i] = base[i, 3]
        b[_W + i] = 0.0
        b[_AL + i] = 0.0
    b[_AC + 0] = -gx
    b[_AC + 1] = -gy
    b[_AC + 2] = -gz

    # ---- forward pass: kinematics, velocities, accelerations (qdd = 0), link wrenches
    for k in range(1, n + 1):
        p = wk[k - 1]
        c = wk[k]
        row = dh[k - 1]
        th = q[k - 1] + row[COL_OFFSET]
        ct, st = math.cos(th), math.sin(th)
        ca, sa = math.cos(row[COL_ALPHA]), math.sin(row[COL_ALPHA])
        la, ld = row[COL_A], row[COL_D]
        # local DH rotation Rz(th) Rx(alpha)
        a00, a01, a02 = ct, -st * ca, st * sa
        a10, a11, a12 = st, ct * ca, -ct * sa
        a20, a21, a22 = 0.0, sa, ca
        for i in range(3):
            r0, r1, r2 = p[_R + 3 * i], p[_R + 3 * i + 1], p[_R + 3 * i + 2]
            c[_R + 3 * i] = r0 * a00 + r1 * a10 + r2 * a20
            c[_R + 3 * i + 1] = r0 * a01 + r1 * a11 + r2 * a21
            c[_R + 3 * i + 2] = r0 * a02 + r1 * a12 + r2 * a22
            c[_O + i] = p[_O + i] + r0 * (la * ct) + r1 * (la * st) + r2 * ld
        # joint axis z_{k-1} (world)
        zx, zy, zz = p[_R + 2], p[_R + 5], p[_R + 8]
        qd = dq[k - 1]
        pwx, pwy, pwz = p[_W], p[_W + 1], p[_W + 2]
        wx, wy, wz = pwx + zx * qd, pwy + zy * qd, pwz + zz * qd
        c[_W], c[_W + 1], c[_W + 2] = wx, wy, wz
        # alpha_k = alpha_{k-1} + w_{k-1} x z qd
        alx = p[_AL] + (pwy * zz - pwz * zy) * qd
        aly = p[_AL + 1] + (pwz * zx - pwx * zz) * qd
        alz = p[_AL + 2] + (pwx * zy - pwy * zx) * qd
        c[_AL], c[_AL + 1], c[_AL + 2] = alx, aly, alz
        # a(o_k) = a(o_{k-1}) + al x r + w x (w x r)
        rx = c[_O] - p[_O]
        ry = c[_O + 1] - p[_O + 1]
        rz = c[_O + 2] - p[_O + 2]
        vx, vy, vz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx
        aox = p[_AC] + (aly * rz - alz * ry) + (wy * vz - wz * vy)
        aoy = p[_AC + 1] + (alz * rx - alx * rz) + (wz * vx - wx * vz)
        aoz = p[_AC + 2] + (alx * ry - aly * rx) + (wx * vy - wy * vx)
        c[_AC], c[_AC + 1], c[_AC + 2] = aox, aoy, aoz
        # COM
        m = row[COL_MASS]
        lcx, lcy, lcz = row[COL_RC], row[COL_RC + 1], row[COL_RC + 2]
        Rk = c[_R:_R + 9]
        sx = Rk[0] * lcx + Rk[1] * lcy + Rk[2] * lcz
        sy = Rk[3] * lcx + Rk[4] * lcy + Rk[5] * lcz
        sz = Rk[6] * lcx + Rk[7] * lcy + Rk[8] * lcz
        c[_C], c[_C + 1], c[_C + 2] = c[_O] + sx, c[_O + 1] + sy, c[_O + 2] + sz
        vx, vy, vz = wy * sz - wz * sy, wz * sx - wx * sz, wx * sy - wy * sx
        acx = aox + (aly * sz - alz * sy) + (wy * vz - wz * vy)
        acy = aoy + (alz * sx - alx * sz) + (wz * vx - wx * vz)
        acz = aoz + (alx * sy - aly * sx) + (wx * vy - wy * vx)
        c[_F], c[_F + 1], c[_F + 2] = m * acx, m * acy, m * acz
        # world inertia Iw = R I R^T
        ixx, iyy, izz = row[COL_I], row[COL_I + 1], row[COL_I + 2]
        ixy, iyz, ixz = row[COL_I + 3], row[COL_I + 4], row[COL_I + 5]
        # T = R I (rows of R times I)
        t00 = Rk[0] * ixx + Rk[1] * ixy + Rk[2] * ixz
        t01 = Rk[0] * ixy + Rk[1] * iyy + Rk[2] * iyz
        t02 = Rk[0] * ixz + Rk[1] * iyz + Rk[2] * izz
        t10 = Rk[3] * ixx + Rk[4] * ixy + Rk[5] * ixz
        t11 = Rk[3] * ixy + Rk[4] * iyy + Rk[5] * iyz
        t12 = Rk[3] * ixz + Rk[4] * iyz + Rk[5] * izz
        t20 = Rk[6] * ixx + Rk[7] * ixy + Rk[8] * ixz
        t21 = Rk[6] * ixy + Rk[7] * iyy + Rk[8] * iyz
        t22 = Rk[6] * ixz + Rk[7] * iyz + Rk[8] * izz
        wxx = t00 * Rk[0] + t01 * Rk[1] + t02 * Rk[2]
        wyy = t10 * Rk[3] + t11 * Rk[4] + t12 * Rk[5]
        wzz = t20 * Rk[6] + t21 * Rk[7] + t22 * Rk[8]
        wxy = t00 * Rk[3] + t01 * Rk[4] + t02 * Rk[5]
        wyz = t10 * Rk[6] + t11 * Rk[7] + t12 * Rk[8]
        wxz = t00 * Rk[6] + t01 * Rk[7] + t02 * Rk[8]
        c[_IW], c[_IW + 1], c[_IW + 2] = wxx, wyy, wzz
        c[_IW + 3], c[_IW + 4], c[_IW + 5] = wxy, wyz, wxz
        # n = Iw al + w x (Iw w)
        Iwx = wxx * wx + wxy * wy + wxz * wz
        Iwy = wxy * wx + wyy * wy + wyz * wz
        Iwz = wxz * wx + wyz * wy + wzz * wz
        c[_N] = wxx * alx + wxy * aly + wxz * alz + (wy * Iwz - wz * Iwy)
        c[_N + 1] = wxy * alx + wyy * aly + wyz * alz + (wz * Iwx - wx * Iwz)
        c[_N + 2] = wxz * alx + wyz * aly + wzz * alz + (wx * Iwy - wy * Iwx)

    # ---- backward pass: h (moments about o_{k-1})
    Fx = Fy = Fz = 0.0
    Mx = My = Mz = 0.0
    for k in range(n, 0, -1):
        p = wk[k - 1]
        c = wk[k]
        ox, oy, oz = p[_O], p[_O + 1], p[_O + 2]
        dx, dy, dz = c[_C] - ox, c[_C + 1] - oy, c[_C + 2] - oz
        ex, ey, ez = c[_O] - ox, c[_O + 1] - oy, c[_O + 2] - oz
        fx, fy, fz = c[_F], c[_F + 1], c[_F + 2]
        Mx = c[_N] + (dy * fz - dz * fy) + Mx + (ey * Fz - ez * Fy)
        My = c[_N + 1] + (dz * fx - dx * fz) + My + (ez * Fx - ex * Fz)
        Mz = c[_N + 2] + (dx * fy - dy * fx) + Mz + (ex * Fy - ey * Fx)
        Fx += fx
        Fy += fy
        Fz += fz
        h[k - 1] = p[_R + 2] * Mx + p[_R + 5] * My + p[_R + 8] * Mz + dh[k - 1, COL_VISCOUS] * dq[k - 1]

    # ---- composite rigid bodies: H
    Mc = 0.0
    hx = hy = hz = 0.0
    cxx = cyy = czz = cxy = cyz = cxz = 0.0
    for i in range(n, 0, -1):
        p = wk[i - 1]
        c = wk[i]
        ox, oy, oz = p[_O], p[_O + 1], p[_O + 2]
        # shift the composite of links i+1..n from o_i to o_{i-1}: e = o_i - o_{i-1}
        ex, ey, ez = c[_O] - ox, c[_O + 1] - oy, c[_O + 2] - oz
        he = hx * ex + hy * ey + hz * ez
        ee = ex * ex + ey * ey + ez * ez
        cxx += 2.0 * he - 2.0 * hx * ex + Mc * (ee - ex * ex)
        cyy += 2.0 * he - 2.0 * hy * ey + Mc * (ee - ey * ey)
        czz += 2.0 * he - 2.0 * hz * ez + Mc * (ee - ez * ez)
        cxy += -(hx * ey + ex * hy) - Mc * ex * ey
        cyz += -(hy * ez + ey * hz) - Mc * ey * ez
        cxz += -(hx * ez + ex * hz) - Mc * ex * ez
        hx += Mc * ex
        hy += Mc * ey
        hz += Mc * ez
        # add link i about o_{i-1}
        m = dh[i - 1, COL_MASS]
        dx, dy, dz = c[_C] - ox, c[_C + 1] - oy, c[_C + 2] - oz
        dd = dx * dx + dy * dy + dz * dz
        cxx += c[_IW] + m * (dd - dx * dx)
        cyy += c[_IW + 1] + m * (dd - dy * dy)
        czz += c[_IW + 2] + m * (dd - dz * dz)
        cxy += c[_IW + 3] - m * dx * dy
        cyz += c[_IW + 4] - m * dy * dz
        cxz += c[_IW + 5] - m * dx * dz
        hx += m * dx
        hy += m * dy
        hz += m * dz
        Mc += m
        # unit acceleration of joint i: moment I_o z about o_{i-1}, force z x hc
        zx, zy, zz = p[_R + 2], p[_R + 5], p[_R + 8]
        Izx = cxx * zx + cxy * zy + cxz * zz
        Izy = cxy * zx + cyy * zy + cyz * zz
        Izz = cxz * zx + cyz * zy + czz * zz
        Fx, Fy, Fz = zy * hz - zz * hy, zz * hx - zx * hz, zx * hy - zy * hx
        H[i - 1, i - 1] = zx * Izx + zy * Izy + zz * Izz + dh[i - 1, COL_MOTOR]
        for j in range(i - 1, 0, -1):
            pj = wk[j - 1]
            rx, ry, rz = ox - pj[_O], oy - pj[_O + 1], oz - pj[_O + 2]
            mx = Izx + (ry * Fz - rz * Fy)
            my = Izy + (rz * Fx - rx * Fz)
            mz = Izz + (rx * Fy - ry * Fx)
            v = pj[_R + 2] * mx + pj[_R + 5] * my + pj[_R + 8] * mz
            H[j - 1, i - 1] = v
            H[i - 1, j - 1] = v

    # ---- tip pose (the chain kernel's: frame rows hold _R and _O at the same columns here)
    e = wk[n]
    px, py, pz, t00, t01, t02, t10, t11, t12, t20, t21, t22, cth, sth = tip_pose(e, tool, False, Y)

    # ---- translational Jacobian rows and tip acceleration
    for k in range(1, n + 1):
        p = wk[k - 1]
        zx, zy, zz = p[_R + 2], p[_R + 5], p[_R + 8]
        rx, ry, rz = px - p[_O], py - p[_O + 1], pz - p[_O + 2]
        J[0, k - 1] = zy * rz - zz * ry
        J[1, k - 1] = zz * rx - zx * rz
        J[2, k - 1] = zx * ry - zy * rx
    wx, wy, wz = e[_W], e[_W + 1], e[_W + 2]
    alx, aly, alz = e[_AL], e[_AL + 1], e[_AL + 2]
    rx, ry, rz = px - e[_O], py - e[_O + 1], pz - e[_O + 2]
    vx, vy, vz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx
    Jdq[0] = e[_AC] + (aly * rz - alz * ry) + (wy * vz - wz * vy) + gx
    Jdq[1] = e[_AC + 1] + (alz * rx - alx * rz) + (wz * vx - wx * vz) + gy
    Jdq[2] = e[_AC + 2] + (alx * ry - aly * rx) + (wx * vy - wy * vx) + gz

    if cth < EULER_SINGULARITY_COS:
        for k in range(n):
            J[3, k] = 0.0
            J[4, k] = 0.0
            J[5, k] = 0.0
        Jdq[3] = 0.0
        Jdq[4] = 0.0
        Jdq[5] = 0.0
        return 1

    # ---- angular rows: dA = L^-1 R^T omega_world
    sph, cph = t21 / cth, t22 / cth
    tth = sth / cth
    # Linv rows
    l01, l02 = sph / cth, cph / cth
    l11, l12 = cph, -sph
    l21, l22 = sph * tth, cph * tth
    # P = L^-1 R^T  (R^T row i = column i of R)
    p00 = l01 * t01 + l02 * t02
    p01 = l01 * t11 + l02 * t12
    p02 = l01 * t21 + l02 * t22
    p10 = l11 * t01 + l12 * t02
    p11 = l11 * t11 + l12 * t12
    p12 = l11 * t21 + l12 * t22
    p20 = t00 + l21 * t01 + l22 * t02
    p21 = t10 + l21 * t11 + l22 * t12
    p22 = t20 + l21 * t21 + l22 * t22
    for k in range(1, n + 1):
        pk = wk[k - 1]
        zx, zy, zz = pk[_R + 2], pk[_R + 5], pk[_R + 8]
        J[3, k - 1] = p00 * zx + p01 * zy + p02 * zz
        J[4, k - 1] = p10 * zx + p11 * zy + p12 * zz
        J[5, k - 1] = p20 * zx + p21 * zy + p22 * zz
    # dA, then ddA = L^-1 (R^T alpha - Ldot dA)
    dA0 = p00 * wx + p01 * wy + p02 * wz
    dA1 = p10 * wx + p11 * wy + p12 * wz
    dA2 = p20 * wx + p21 * wy + p22 * wz
    bx = t00 * alx + t10 * aly + t20 * alz
    by = t01 * alx + t11 * aly + t21 * alz
    bz = t02 * alx + t12 * aly + t22 * alz
    # Ldot dA (frames.body_rate_map_dot)
    bx -= -cth * dA1 * dA0
    by -= (cph * cth * dA2 - sph * sth * dA1) * dA0 - sph * dA2 * dA1
    bz -= (-sph * cth * dA2 - cph * sth * dA1) * dA0 - cph * dA2 * dA1
    Jdq[3] = l01 * by + l02 * bz
    Jdq[4] = l11 * by + l12 * bz
    Jdq[5] = bx + l21 * by + l22 * bz
    return 0


@njit(cache=True)
def spatial_arm_potential(q, dh, base, gravity):
    """Gravitational potential energy of the links ``U = -sum_k m_k g . p_com_k`` [J]."""
    n = q.shape[0]
    R = np.empty(9)
    o = np.empty(3)
    for i in range(3):
        for j in range(3):
            R[3 * i + j] = base[i, j]
        o[i] = base[i, 3]
    U = 0.0
    for k in range(n):
        row = dh[k]
        th = q[k] + row[COL_OFFSET]
        ct, st = math.cos(th), math.sin(th)
        ca, sa = math.cos(row[COL_ALPHA]), math.sin(row[COL_ALPHA])
        la, ld = row[COL_A], row[COL_D]
        for i in range(3):
            r0, r1, r2 = R[3 * i], R[3 * i + 1], R[3 * i + 2]
            o[i] += r0 * (la * ct) + r1 * (la * st) + r2 * ld
            R[3 * i] = r0 * ct + r1 * st
            R[3 * i + 1] = -r0 * st * ca + r1 * ct * ca + r2 * sa
            R[3 * i + 2] = r0 * st * sa - r1 * ct * sa + r2 * ca
        m = row[COL_MASS]
        for i in range(3):
            pc = o[i] + R[3 * i] * row[COL_RC] + R[3 * i + 1] * row[COL_RC + 1] + R[3 * i + 2] * row[COL_RC + 2]
            U -= m * gravity[i] * pc
    return U


@njit(cache=True)
def spatial_arm_tip(q, dh, base, tool, T, Jg):
    """Tip transform ``T`` (4x4) and world geometric Jacobian ``Jg`` (6 x n: v; omega).

    Defined everywhere (no Euler angles); used by inverse kinematics and the tests.
    """
    n = q.shape[0]
    R = np.empty(9)
    o = np.empty(3)
    Z = np.empty((n, 3))
    P = np.empty((n, 3))
    for i in range(3):
        for j in range(3):
            R[3 * i + j] = base[i, j]
        o[i] = base[i, 3]
    for k in range(n):
        row = dh[k]
        for i in range(3):
            Z[k, i] = R[3 * i + 2]
            P[k, i] = o[i]
        th = q[k] + row[COL_OFFSET]
        ct, st = math.cos(th), math.sin(th)
        ca, sa = math.cos(row[COL_ALPHA]), math.sin(row[COL_ALPHA])
        la, ld = row[COL_A], row[COL_D]
        for i in range(3):
            r0, r1, r2 = R[3 * i], R[3 * i + 1], R[3 * i + 2]
            o[i] += r0 * (la * ct) + r1 * (la * st) + r2 * ld
            R[3 * i] = r0 * ct + r1 * st
            R[3 * i + 1] = -r0 * st * ca + r1 * ct * ca + r2 * sa
            R[3 * i + 2] = r0 * st * sa - r1 * ct * sa + r2 * ca
    for i in range(3):
        for j in range(3):
            T[i, j] = R[3 * i] * tool[0, j] + R[3 * i + 1] * tool[1, j] + R[3 * i + 2] * tool[2, j]
        T[i, 3] = o[i] + R[3 * i] * tool[0, 3] + R[3 * i + 1] * tool[1, 3] + R[3 * i + 2] * tool[2, 3]
        T[3, i] = 0.0
    T[3, 3] = 1.0
    for k in range(n):
        zx, zy, zz = Z[k, 0], Z[k, 1], Z[k, 2]
        rx, ry, rz = T[0, 3] - P[k, 0], T[1, 3] - P[k, 1], T[2, 3] - P[k, 2]
        Jg[0, k] = zy * rz - zz * ry
        Jg[1, k] = zz * rx - zx * rz
        Jg[2, k] = zx * ry - zy * rx
        Jg[3, k] = zx
        Jg[4, k] = zy
        Jg[5, k] = zz
