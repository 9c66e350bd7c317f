"""Numba kernels of a spatial serial chain with general joints (URDF-style; docs/model.md s.4).

Kept for the numba code that still calls it: pre-flight's inverse kinematics (coopctrl/analysis/preflight_ik.py)
and the cooperative kernels; ChainArm calls the compiled core (plants/core/chain_arm.h). It goes with its last
caller (tests/test_plants_without_numba.py lists it).

The same outputs as the DH kernel :func:`plants.arms._spatial_kernels.spatial_arm_terms`, for a
chain whose joint ``k`` sits at a fixed transform ``origin_k`` in the frame of link ``k - 1`` and
moves about (revolute) or along (prismatic) a unit ``axis_k`` of that joint frame:

.. math::

    {}^0T_k = {}^0T_{k-1} \\; \\mathrm{origin}_k \\; M_k(q_k), \\qquad
    M_k = \\mathrm{Rot}(\\mathrm{axis}_k, q_k) \\;\\text{or}\\; \\mathrm{Trans}(\\mathrm{axis}_k\\, q_k)

and then ``H(q) qdd + h(q, dq) = tau``, ``Y = Phi(q)`` (ZYX Euler, docs/model.md s.2),
``J = dY/dq`` (analytic: ``dA = L(A)^-1 R^T omega_world``) and ``dJ dq``.

Algorithm (all quantities in world coordinates, reference point of body ``k`` = the origin
``o_k`` of link frame ``k``, which lies on joint ``k``'s axis for a revolute joint):

* forward kinematics and the recursive Newton-Euler forward pass with ``qdd = 0`` and the base
  accelerating with ``-g`` (gravity in ``h``): ``a(o_k) = a(o_{k-1}) + alpha_{k-1} x d +
  w_{k-1} x (w_{k-1} x d)``, ``d = o_k - o_{k-1}`` (``o_k`` is a point of body ``k - 1``), plus
  the Coriolis term ``2 w_{k-1} x u_k dq_k`` for a prismatic joint;
* backward pass: subtree wrench about ``o_k``; ``h_k = u_k . M`` (revolute) or ``u_k . F``
  (prismatic), plus ``viscous_k dq_k`` and the smoothed Coulomb friction;
* composite rigid bodies for ``H``: composites about ``o_i`` with their first moment; the unit
  acceleration of a revolute joint gives (moment ``I_c u``, force ``u x h_c``), of a prismatic
  joint (moment ``h_c x u``, force ``M_c u``); ``motor_inertia`` is added to ``H``'s diagonal;
* the geometric Jacobian ``(u x (p - o_k); u)`` or ``(u; 0)``, mapped to Euler rates;
  ``Jdq`` from the tip acceleration of the ``qdd = 0`` pass with gravity removed.

Joint table layout (one row per moving joint, float64 ``(n, 32)``)::

    [type, ox, oy, oz, R00..R22 (9, row-major), ax, ay, az, mass, rcx, rcy, rcz,
     Ixx, Iyy, Izz, Ixy, Iyz, Ixz, motor_inertia, viscous, coulomb, 0, 0, 0]

``type``: :data:`JOINT_REVOLUTE_Z` (revolute about +z of the joint frame, the fast path),
:data:`JOINT_REVOLUTE` (about ``axis``) or :data:`JOINT_PRISMATIC` (along ``axis``).
``(ox, oy, oz)`` [m] and ``R`` are ``origin_k``; the mass [kg], the COM ``rc`` [m] and the
inertia about the COM [kg m^2] are in link frame ``k`` (after the joint motion);
``motor_inertia`` [kg m^2 or kg] is added to ``H[k, k]``; ``viscous`` [N m s/rad or N s/m] adds
``viscous * dq_k`` to ``h_k`` and ``coulomb`` [N m or N] adds the smoothed Coulomb friction
``coulomb * tanh(dq_k / COULOMB_SMOOTHING)``.

No Python objects, no numpy linear algebra: loops are written out. :func:`chain_arm_terms_into`
allocates nothing (its work array is the caller's); :func:`chain_arm_terms` allocates that one
small array per call.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.frames import EULER_SINGULARITY_COS

from plants.arms.chain_table import (  # noqa: F401 (the layout, read here by name)
    CHAIN_COLUMNS, COL_AXIS, COL_COULOMB, COL_I, COL_MASS, COL_MOTOR, COL_ORIGIN, COL_RC, COL_ROT, COL_TYPE,
    COL_VISCOUS, COULOMB_SMOOTHING, JOINT_PRISMATIC, JOINT_REVOLUTE, JOINT_REVOLUTE_Z,
)

# Work-array layout, one row per body k = 0..n (body 0 = base).
_R = 0  # 9: world rotation of link frame k (row-major)
_O = 9  # 3: world origin of link frame k
_U = 12  # 3: world axis of joint k
_W = 15  # 3: angular velocity of body k
_AL = 18  # 3: angular acceleration of body k (qdd = 0)
_AC = 21  # 3: linear acceleration of o_k as a point of body k (incl. -g)
_C = 24  # 3: COM of link k (world)
_IW = 27  # 6: world inertia of link k about its COM: xx, yy, zz, xy, yz, xz
_F = 33  # 3: inertial force of link k
_N = 36  # 3: inertial moment of link k about its COM
_WORK = 39
#: Columns of the work array of :func:`chain_arm_terms_into` (one row per body, base included).
CHAIN_WORK_WIDTH = _WORK


@njit(cache=True, inline="always")
def _link_frame(p, row, qk, c):
    """Write link frame k (``_R``, ``_O``) and the world joint axis ``_U`` into ``c``:
    ``R_k = R_{k-1} (R_o M(q))``, ``o_k = o_{k-1} + R_{k-1} p_o`` (+ ``u q`` if prismatic)."""
    kind = int(row[COL_TYPE])
    o00, o01, o02 = row[COL_ROT], row[COL_ROT + 1], row[COL_ROT + 2]
    o10, o11, o12 = row[COL_ROT + 3], row[COL_ROT + 4], row[COL_ROT + 5]
    o20, o21, o22 = row[COL_ROT + 6], row[COL_ROT + 7], row[COL_ROT + 8]
    # local rotation L = R_o M(q) and local joint axis a_o = R_o axis
    if kind == JOINT_REVOLUTE_Z:
        ct, st = math.cos(qk), math.sin(qk)
        l00, l01, l02 = ct * o00 + st * o01, ct * o01 - st * o00, o02
        l10, l11, l12 = ct * o10 + st * o11, ct * o11 - st * o10, o12
        l20, l21, l22 = ct * o20 + st * o21, ct * o21 - st * o20, o22
        ax_, ay_, az_ = o02, o12, o22
    else:
        ax, ay, az = row[COL_AXIS], row[COL_AXIS + 1], row[COL_AXIS + 2]
        ax_ = o00 * ax + o01 * ay + o02 * az
        ay_ = o10 * ax + o11 * ay + o12 * az
        az_ = o20 * ax + o21 * ay + o22 * az
        if kind == JOINT_PRISMATIC:
            l00, l01, l02 = o00, o01, o02
            l10, l11, l12 = o10, o11, o12
            l20, l21, l22 = o20, o21, o22
        else:
            # Rodrigues: Rot = c I + s [a]x + (1 - c) a a^T
            ct, st = math.cos(qk), math.sin(qk)
            vt = 1.0 - ct
            m00, m01, m02 = ct + vt * ax * ax, vt * ax * ay - st * az, vt * ax * az + st * ay
            m10, m11, m12 = vt * ax * ay + st * az, ct + vt * ay * ay, vt * ay * az - st * ax
            m20, m21, m22 = vt * ax * az - st * ay, vt * ay * az + st * ax, ct + vt * az * az
            l00 = o00 * m00 + o01 * m10 + o02 * m20
            l01 = o00 * m01 + o01 * m11 + o02 * m21
            l02 = o00 * m02 + o01 * m12 + o02 * m22
            l10 = o10 * m00 + o11 * m10 + o12 * m20
            l11 = o10 * m01 + o11 * m11 + o12 * m21
            l12 = o10 * m02 + o11 * m12 + o12 * m22
            l20 = o20 * m00 + o21 * m10 + o22 * m20
            l21 = o20 * m01 + o21 * m11 + o22 * m21
            l22 = o20 * m02 + o21 * m12 + o22 * m22
    ox, oy, oz = row[COL_ORIGIN], row[COL_ORIGIN + 1], row[COL_ORIGIN + 2]
    for i in range(3):
        r0, r1, r2 = p[_R + 3 * i], p[_R + 3 * i + 1], p[_R + 3 * i + 2]
        c[_R + 3 * i] = r0 * l00 + r1 * l10 + r2 * l20
        c[_R + 3 * i + 1] = r0 * l01 + r1 * l11 + r2 * l21
        c[_R + 3 * i + 2] = r0 * l02 + r1 * l12 + r2 * l22
        u = r0 * ax_ + r1 * ay_ + r2 * az_
        c[_U + i] = u
        o = p[_O + i] + r0 * ox + r1 * oy + r2 * oz
        if kind == JOINT_PRISMATIC:
            o += u * qk
        c[_O + i] = o


@njit(cache=True, inline="always")
def tip_pose(e, tool, own_chart, Y):
    """Write the node pose ``Y`` (6) from the last link's frame ``e`` (a work row: ``_R``, ``_O``) and ``tool``
    (4x4): ``R_tip = R_n tool_R``, ``p_tip = o_n + R_n tool_p``; the angles are ZYX Euler angles of ``R_tip``
    (``theta = atan2(-R_20, sqrt(R_21^2 + R_22^2))``), or zero in the node's own chart. Returns
    ``(px, py, pz, R_tip row by row, cos theta, sin theta)`` (``1, 0`` in the own chart). The one tip
    computation of :func:`chain_arm_terms_into`, :func:`chain_arm_pose_into` and the DH kernel
    :func:`plants.arms._spatial_kernels.spatial_arm_terms` (whose frame rows also hold ``_R`` at 0 and ``_O``
    at 9)."""
    Rn = e[_R:_R + 9]
    t00 = Rn[0] * tool[0, 0] + Rn[1] * tool[1, 0] + Rn[2] * tool[2, 0]
    t10 = Rn[3] * tool[0, 0] + Rn[4] * tool[1, 0] + Rn[5] * tool[2, 0]
    t20 = Rn[6] * tool[0, 0] + Rn[7] * tool[1, 0] + Rn[8] * tool[2, 0]
    t01 = Rn[0] * tool[0, 1] + Rn[1] * tool[1, 1] + Rn[2] * tool[2, 1]
    t11 = Rn[3] * tool[0, 1] + Rn[4] * tool[1, 1] + Rn[5] * tool[2, 1]
    t21 = Rn[6] * tool[0, 1] + Rn[7] * tool[1, 1] + Rn[8] * tool[2, 1]
    t02 = Rn[0] * tool[0, 2] + Rn[1] * tool[1, 2] + Rn[2] * tool[2, 2]
    t12 = Rn[3] * tool[0, 2] + Rn[4] * tool[1, 2] + Rn[5] * tool[2, 2]
    t22 = Rn[6] * tool[0, 2] + Rn[7] * tool[1, 2] + Rn[8] * tool[2, 2]
    px = e[_O] + Rn[0] * tool[0, 3] + Rn[1] * tool[1, 3] + Rn[2] * tool[2, 3]
    py = e[_O + 1] + Rn[3] * tool[0, 3] + Rn[4] * tool[1, 3] + Rn[5] * tool[2, 3]
    pz = e[_O + 2] + Rn[6] * tool[0, 3] + Rn[7] * tool[1, 3] + Rn[8] * tool[2, 3]
    Y[0], Y[1], Y[2] = px, py, pz
    if own_chart:
        Y[3] = 0.0
        Y[4] = 0.0
        Y[5] = 0.0
        cth, sth = 1.0, 0.0
    else:
        cth = math.sqrt(t21 * t21 + t22 * t22)
        sth = -t20
        Y[3] = math.atan2(t10, t00)
        Y[4] = math.atan2(sth, cth)
        Y[5] = math.atan2(t21, t22)
    return px, py, pz, t00, t01, t02, t10, t11, t12, t20, t21, t22, cth, sth


@njit(cache=True, _nrt=False)
def chain_arm_pose_into(q, table, base, tool, own_chart, wk, Y):
    """The node pose ``Y`` (6) of :func:`chain_arm_terms_into` alone, bit for bit (the same link frames and
    tip computation, :func:`tip_pose`), without the velocities, the dynamics or the Jacobian: forward
    kinematics. ``wk`` as there (rows ``0..n`` overwritten). Returns 1 where :func:`chain_arm_terms_into`
    does (the tip's Euler angles at the singularity of ``L``: ``cos theta < EULER_SINGULARITY_COS``), else
    0. Allocates nothing."""
    n = q.shape[0]
    b = wk[0]
    for i in range(3):
        for j in range(3):
            b[_R + 3 * i + j] = base[i, j]
        b[_O + i] = base[i, 3]
    for k in range(1, n + 1):
        _link_frame(wk[k - 1], table[k - 1], q[k - 1], wk[k])
    cth = tip_pose(wk[n], tool, own_chart, Y)[12]
    return 1 if cth < EULER_SINGULARITY_COS else 0


@njit(cache=True)
def chain_arm_terms(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq):
    """:func:`chain_arm_terms_into` with a work array of its own (one allocation per call)."""
    wk = np.empty((q.shape[0] + 1, CHAIN_WORK_WIDTH))
    return chain_arm_terms_into(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq, wk, False, np.empty((3, 3)))


@njit(cache=True)
def chain_arm_terms_own_chart(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq, chart):
    """:func:`chain_arm_terms_into` with the node in its own chart (``own_chart`` True): ``Y[3:6] = 0``,
    ``chart`` (3x3) receives the node's world rotation ``R_tip(q)``; one allocation per call."""
    wk = np.empty((q.shape[0] + 1, CHAIN_WORK_WIDTH))
    return chain_arm_terms_into(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq, wk, True, chart)


@njit(cache=True, _nrt=False)
def chain_arm_terms_into(q, dq, table, base, tool, gravity, H, h, Y, J, Jdq, wk, own_chart, chart):
    """Fill ``H`` (n x n), ``h`` (n), ``Y`` (6), ``J`` (6 x n) and ``Jdq`` (6) in place; allocates nothing.

    Args:
        q: Joint positions [rad or m], (n,).
        dq: Joint rates [rad/s or m/s], (n,).
        table: Joint table, (n, 32), see the module docstring.
        base: World pose of the arm base frame, 4x4 [m].
        tool: Transform from the last link frame to the node frame, 4x4 [m].
        gravity: Gravity acceleration [m/s^2], (3,), e.g. (0, 0, -9.81).
        H: Out: joint-space inertia.
        h: Out: Coriolis, centrifugal, gravity and viscous forces.
        Y: Out: node pose (position [m], ZYX Euler angles [rad]).
        J: Out: analytic Jacobian.
        Jdq: Out: ``dJ/dt dq`` [m/s^2, rad/s^2].
        wk: Work array, float64 ``(n_rows, CHAIN_WORK_WIDTH)`` with ``n_rows >= n + 1`` (one row
            per body, base included; rows past ``n`` are not touched); overwritten.
        own_chart: False: the node's angles are the book's world ZYX Euler angles of ``R_tip``.
            True: they are taken in the node's own chart for this evaluation (docs/model.md s.2,
            rotation charts): ``C = R_tip(q)``, ``A = 0``, so ``L(0)`` is a permutation and the
            angular rows ``dA = L(0)^-1 R_tip^T omega_world`` (body rates) exist at every pose.
        chart: Out (``own_chart`` True): the chart ``C = R_tip(q)`` (3x3); untouched otherwise.

    Returns:
        0 on success; 1 if the tip's Euler angles are at the singularity of ``L`` (then the
        angular rows of ``J`` and ``Jdq`` are set to zero, everything else is valid).
    """
    n = q.shape[0]
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
        row = table[k - 1]
        _link_frame(p, row, q[k - 1], c)
        prismatic = int(row[COL_TYPE]) == JOINT_PRISMATIC
        ux, uy, uz = c[_U], c[_U + 1], c[_U + 2]
        qd = dq[k - 1]
        pwx, pwy, pwz = p[_W], p[_W + 1], p[_W + 2]
        palx, paly, palz = p[_AL], p[_AL + 1], p[_AL + 2]
        # a(o_k) as a point of body k-1
        rx = c[_O] - p[_O]
        ry = c[_O + 1] - p[_O + 1]
        rz = c[_O + 2] - p[_O + 2]
        vx, vy, vz = pwy * rz - pwz * ry, pwz * rx - pwx * rz, pwx * ry - pwy * rx
        aox = p[_AC] + (paly * rz - palz * ry) + (pwy * vz - pwz * vy)
        aoy = p[_AC + 1] + (palz * rx - palx * rz) + (pwz * vx - pwx * vz)
        aoz = p[_AC + 2] + (palx * ry - paly * rx) + (pwx * vy - pwy * vx)
        if prismatic:
            wx, wy, wz = pwx, pwy, pwz
            alx, aly, alz = palx, paly, palz
            aox += 2.0 * (pwy * uz - pwz * uy) * qd
            aoy += 2.0 * (pwz * ux - pwx * uz) * qd
            aoz += 2.0 * (pwx * uy - pwy * ux) * qd
        else:
            wx, wy, wz = pwx + ux * qd, pwy + uy * qd, pwz + uz * qd
            alx = palx + (pwy * uz - pwz * uy) * qd
            aly = paly + (pwz * ux - pwx * uz) * qd
            alz = palz + (pwx * uy - pwy * ux) * qd
        c[_W], c[_W + 1], c[_W + 2] = wx, wy, wz
        c[_AL], c[_AL + 1], c[_AL + 2] = alx, aly, alz
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

    # ---- backward pass: h (subtree wrench about o_k)
    Fx = Fy = Fz = 0.0
    Mx = My = Mz = 0.0
    for k in range(n, 0, -1):
        c = wk[k]
        ox, oy, oz = c[_O], c[_O + 1], c[_O + 2]
        if k < n:
            nx_ = wk[k + 1]
            ex, ey, ez = nx_[_O] - ox, nx_[_O + 1] - oy, nx_[_O + 2] - oz
            Mx += ey * Fz - ez * Fy
            My += ez * Fx - ex * Fz
            Mz += ex * Fy - ey * Fx
        dx, dy, dz = c[_C] - ox, c[_C + 1] - oy, c[_C + 2] - oz
        fx, fy, fz = c[_F], c[_F + 1], c[_F + 2]
        Mx += c[_N] + (dy * fz - dz * fy)
        My += c[_N + 1] + (dz * fx - dx * fz)
        Mz += c[_N + 2] + (dx * fy - dy * fx)
        Fx += fx
        Fy += fy
        Fz += fz
        if int(table[k - 1, COL_TYPE]) == JOINT_PRISMATIC:
            s = c[_U] * Fx + c[_U + 1] * Fy + c[_U + 2] * Fz
        else:
            s = c[_U] * Mx + c[_U + 1] * My + c[_U + 2] * Mz
        s += table[k - 1, COL_VISCOUS] * dq[k - 1]
        if table[k - 1, COL_COULOMB] != 0.0:
            s += table[k - 1, COL_COULOMB] * math.tanh(dq[k - 1] / COULOMB_SMOOTHING)
        h[k - 1] = s

    # ---- composite rigid bodies: H (composite of links i..n about o_i)
    Mc = 0.0
    hx = hy = hz = 0.0
    cxx = cyy = czz = cxy = cyz = cxz = 0.0
    for i in range(n, 0, -1):
        c = wk[i]
        ox, oy, oz = c[_O], c[_O + 1], c[_O + 2]
        if i < n:
            nx_ = wk[i + 1]
            ex, ey, ez = nx_[_O] - ox, nx_[_O + 1] - oy, nx_[_O + 2] - oz
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
        m = table[i - 1, COL_MASS]
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
        ux, uy, uz = c[_U], c[_U + 1], c[_U + 2]
        if int(table[i - 1, COL_TYPE]) == JOINT_PRISMATIC:
            Fx, Fy, Fz = Mc * ux, Mc * uy, Mc * uz
            Izx, Izy, Izz = hy * uz - hz * uy, hz * ux - hx * uz, hx * uy - hy * ux
            H[i - 1, i - 1] = ux * Fx + uy * Fy + uz * Fz + table[i - 1, COL_MOTOR]
        else:
            Izx = cxx * ux + cxy * uy + cxz * uz
            Izy = cxy * ux + cyy * uy + cyz * uz
            Izz = cxz * ux + cyz * uy + czz * uz
            Fx, Fy, Fz = uy * hz - uz * hy, uz * hx - ux * hz, ux * hy - uy * hx
            H[i - 1, i - 1] = ux * Izx + uy * Izy + uz * Izz + table[i - 1, COL_MOTOR]
        for j in range(i - 1, 0, -1):
            pj = wk[j]
            if int(table[j - 1, COL_TYPE]) == JOINT_PRISMATIC:
                v = pj[_U] * Fx + pj[_U + 1] * Fy + pj[_U + 2] * Fz
            else:
                rx, ry, rz = ox - pj[_O], oy - pj[_O + 1], oz - pj[_O + 2]
                mx = Izx + (ry * Fz - rz * Fy)
                my = Izy + (rz * Fx - rx * Fz)
                mz = Izz + (rx * Fy - ry * Fx)
                v = pj[_U] * mx + pj[_U + 1] * my + pj[_U + 2] * mz
            H[j - 1, i - 1] = v
            H[i - 1, j - 1] = v

    # ---- tip pose
    e = wk[n]
    px, py, pz, t00, t01, t02, t10, t11, t12, t20, t21, t22, cth, sth = tip_pose(e, tool, own_chart, Y)
    if own_chart:
        chart[0, 0], chart[0, 1], chart[0, 2] = t00, t01, t02
        chart[1, 0], chart[1, 1], chart[1, 2] = t10, t11, t12
        chart[2, 0], chart[2, 1], chart[2, 2] = t20, t21, t22

    # ---- translational Jacobian rows and tip acceleration
    for k in range(1, n + 1):
        c = wk[k]
        ux, uy, uz = c[_U], c[_U + 1], c[_U + 2]
        if int(table[k - 1, COL_TYPE]) == JOINT_PRISMATIC:
            J[0, k - 1], J[1, k - 1], J[2, k - 1] = ux, uy, uz
        else:
            rx, ry, rz = px - c[_O], py - c[_O + 1], pz - c[_O + 2]
            J[0, k - 1] = uy * rz - uz * ry
            J[1, k - 1] = uz * rx - ux * rz
            J[2, k - 1] = ux * ry - uy * rx
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
    if own_chart:
        sph, cph = 0.0, 1.0
    else:
        sph, cph = t21 / cth, t22 / cth
    tth = sth / cth
    l01, l02 = sph / cth, cph / cth
    l11, l12 = cph, -sph
    l21, l22 = sph * tth, cph * tth
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
        if int(table[k - 1, COL_TYPE]) == JOINT_PRISMATIC:
            J[3, k - 1] = 0.0
            J[4, k - 1] = 0.0
            J[5, k - 1] = 0.0
            continue
        c = wk[k]
        ux, uy, uz = c[_U], c[_U + 1], c[_U + 2]
        J[3, k - 1] = p00 * ux + p01 * uy + p02 * uz
        J[4, k - 1] = p10 * ux + p11 * uy + p12 * uz
        J[5, k - 1] = p20 * ux + p21 * uy + p22 * uz
    dA0 = p00 * wx + p01 * wy + p02 * wz
    dA1 = p10 * wx + p11 * wy + p12 * wz
    dA2 = p20 * wx + p21 * wy + p22 * wz
    bx = t00 * alx + t10 * aly + t20 * alz
    by = t01 * alx + t11 * aly + t21 * alz
    bz = t02 * alx + t12 * aly + t22 * alz
    bx -= -cth * dA1 * dA0
    by -= (cph * cth * dA2 - sph * sth * dA1) * dA0 - sph * dA2 * dA1
    bz -= (-sph * cth * dA2 - cph * sth * dA1) * dA0 - cph * dA2 * dA1
    Jdq[3] = l01 * by + l02 * bz
    Jdq[4] = l11 * by + l12 * bz
    Jdq[5] = bx + l21 * by + l22 * bz
    return 0


@njit(cache=True)
def chain_arm_potential(q, table, base, gravity):
    """Gravitational potential energy of the links ``U = -sum_k m_k g . p_com_k`` [J]."""
    return chain_arm_potential_into(q, table, base, gravity, np.empty((q.shape[0] + 1, _WORK)))


@njit(cache=True)
def chain_arm_potential_into(q, table, base, gravity, wk):
    """:func:`chain_arm_potential` on the caller's work rows ``wk`` (at least ``(n + 1, CHAIN_WORK_WIDTH)``):
    allocates nothing."""
    n = q.shape[0]
    for i in range(3):
        for j in range(3):
            wk[0, _R + 3 * i + j] = base[i, j]
        wk[0, _O + i] = base[i, 3]
    U = 0.0
    for k in range(1, n + 1):
        row = table[k - 1]
        c = wk[k]
        _link_frame(wk[k - 1], row, q[k - 1], c)
        m = row[COL_MASS]
        for i in range(3):
            pc = c[_O + i] + c[_R + 3 * i] * row[COL_RC] + c[_R + 3 * i + 1] * row[COL_RC + 1] + c[_R + 3 * i + 2] * row[COL_RC + 2]
            U -= m * gravity[i] * pc
    return U


@njit(cache=True)
def chain_arm_tip(q, table, base, tool, T, Jg):
    """Tip transform ``T`` (4x4) and world geometric Jacobian ``Jg`` (6 x n: v; omega).

    Defined everywhere (no Euler angles); used by inverse kinematics and the tests.
    """
    n = q.shape[0]
    wk = np.empty((n + 1, _WORK))
    for i in range(3):
        for j in range(3):
            wk[0, _R + 3 * i + j] = base[i, j]
        wk[0, _O + i] = base[i, 3]
    for k in range(1, n + 1):
        _link_frame(wk[k - 1], table[k - 1], q[k - 1], wk[k])
    e = wk[n]
    for i in range(3):
        for j in range(3):
            T[i, j] = e[_R + 3 * i] * tool[0, j] + e[_R + 3 * i + 1] * tool[1, j] + e[_R + 3 * i + 2] * tool[2, j]
        T[i, 3] = e[_O + i] + e[_R + 3 * i] * tool[0, 3] + e[_R + 3 * i + 1] * tool[1, 3] + e[_R + 3 * i + 2] * tool[2, 3]
        T[3, i] = 0.0
    T[3, 3] = 1.0
    for k in range(1, n + 1):
        c = wk[k]
        ux, uy, uz = c[_U], c[_U + 1], c[_U + 2]
        if int(table[k - 1, COL_TYPE]) == JOINT_PRISMATIC:
            Jg[0, k - 1], Jg[1, k - 1], Jg[2, k - 1] = ux, uy, uz
            Jg[3, k - 1], Jg[4, k - 1], Jg[5, k - 1] = 0.0, 0.0, 0.0
            continue
        rx, ry, rz = T[0, 3] - c[_O], T[1, 3] - c[_O + 1], T[2, 3] - c[_O + 2]
        Jg[0, k - 1] = uy * rz - uz * ry
        Jg[1, k - 1] = uz * rx - ux * rz
        Jg[2, k - 1] = ux * ry - uy * rx
        Jg[3, k - 1] = ux
        Jg[4, k - 1] = uy
        Jg[5, k - 1] = uz
