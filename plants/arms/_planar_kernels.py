"""Numba kernels of a planar serial arm in the vertical x-z plane (docs/model.md s.2 and s.4).

Kept for the numba code that still calls it: pre-flight's inverse kinematics (coopctrl/analysis/preflight_ik.py)
and the cooperative kernels; PlanarArm calls the compiled core (plants/core/planar_arm.h). It goes with its last
caller (tests/test_plants_without_numba.py lists it).

Planar reduction: node pose ``Y = (x, z, theta)``, ``theta`` [rad] from +x towards +z, all
joints revolute about the axis normal to the x-z plane, gravity ``(gx, gz)`` [m/s^2]. Same
equations as the spatial kernels, (166)-(172), with ``L = 1``:

.. math::

    H(q)\\ddot q + h(q, \\dot q) = \\tau, \\qquad Y = \\Phi(q), \\qquad
    \\dot Y = J \\dot q, \\qquad \\ddot Y = J \\ddot q + \\dot J \\dot q

Link table layout (one row per link, float64 ``(n, 7)``)::

    [length, mass, rc_x, rc_y, Izz, motor_inertia, viscous]

``length`` [m] from joint k to joint k+1 along the link's x axis, ``mass`` [kg], the COM
``(rc_x, rc_y)`` [m] in the link frame (``rc_y`` perpendicular towards +theta), ``Izz`` the
inertia about the COM [kg m^2], ``motor_inertia`` [kg m^2] added to ``H``'s diagonal and
``viscous`` [N m s/rad] adding ``viscous * dq`` to ``h``. ``base = (x, z, theta)`` is the pose
of joint 1's frame at ``q = 0``; ``tool = (dx, dz, dtheta)`` is the node frame in the last link
frame (offset from the end of the last link).

2-D conventions: a "cross product" of a rate ``w`` with a vector ``r`` is ``w * (-r_z, r_x)``,
and of two vectors ``r1 x r2 = r1_x r2_z - r1_z r2_x``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

COL_LENGTH, COL_MASS, COL_RCX, COL_RCY, COL_IZZ, COL_MOTOR, COL_VISCOUS = 0, 1, 2, 3, 4, 5, 6
LINK_COLUMNS = 7

# Work-array layout per joint/link k = 0..n-1 (row n holds the end of the last link).
_O = 0  # 2: joint k position (row n: end of last link)
_TH = 2  # 1: absolute angle of link k
_W = 3  # 1: angular velocity of link k
_A = 4  # 2: acceleration of o_k (incl. -g), as a point of link k (qdd = 0)
_C = 6  # 2: COM of link k
_F = 8  # 2: inertial force of link k
_WORK = 10
#: Columns of the work array of :func:`planar_arm_terms_into`.
PLANAR_WORK_WIDTH = _WORK


@njit(cache=True)
def planar_arm_terms(q, dq, links, base, tool, gravity, H, h, Y, J, Jdq):
    """:func:`planar_arm_terms_into` with a work array of its own (one allocation per call)."""
    wk = np.empty((q.shape[0] + 1, PLANAR_WORK_WIDTH))
    return planar_arm_terms_into(q, dq, links, base, tool, gravity, H, h, Y, J, Jdq, wk)


@njit(cache=True, _nrt=False)
def planar_arm_terms_into(q, dq, links, base, tool, gravity, H, h, Y, J, Jdq, wk):
    """Fill ``H`` (n x n), ``h`` (n), ``Y`` (3), ``J`` (3 x n), ``Jdq`` (3) in place; return 0.

    Allocates nothing: ``wk`` is a float64 work array ``(n_rows, PLANAR_WORK_WIDTH)``,
    ``n_rows >= n + 1`` (rows past ``n`` are not touched), overwritten.

    Args:
        q: Joint angles [rad], (n,).
        dq: Joint rates [rad/s], (n,).
        links: Link table, (n, 7), see the module docstring.
        base: ``(x, z, theta)`` of joint 1 [m, m, rad].
        tool: ``(dx, dz, dtheta)`` of the node frame in the last link frame [m, m, rad].
        gravity: ``(gx, gz)`` [m/s^2], e.g. (0, -9.81).
        H: Out: joint-space inertia [kg m^2].
        h: Out: Coriolis, centrifugal, gravity and viscous torques [N m].
        Y: Out: node pose ``(x, z, theta)``.
        J: Out: Jacobian ``dY/dq``.
        Jdq: Out: ``dJ/dt dq`` [m/s^2, m/s^2, rad/s^2].
        wk: Work array (see above).
    """
    n = q.shape[0]
    gx, gz = gravity[0], gravity[1]
    ox, oz = base[0], base[1]
    th = base[2]
    w = 0.0
    ax, az = -gx, -gz
    for k in range(n):
        r = wk[k]
        th += q[k]
        w += dq[k]
        r[_O], r[_O + 1], r[_TH], r[_W] = ox, oz, th, w
        r[_A], r[_A + 1] = ax, az
        ct, st = math.cos(th), math.sin(th)
        row = links[k]
        # COM and its acceleration (alpha = 0 with qdd = 0): a_c = a_o - w^2 d
        sx = ct * row[COL_RCX] - st * row[COL_RCY]
        sz = st * row[COL_RCX] + ct * row[COL_RCY]
        r[_C], r[_C + 1] = ox + sx, oz + sz
        m = row[COL_MASS]
        w2 = w * w
        r[_F] = m * (ax - w2 * sx)
        r[_F + 1] = m * (az - w2 * sz)
        # next joint
        lx, lz = row[COL_LENGTH] * ct, row[COL_LENGTH] * st
        ox += lx
        oz += lz
        ax -= w2 * lx
        az -= w2 * lz
    e = wk[n]
    e[_O], e[_O + 1], e[_TH], e[_W], e[_A], e[_A + 1] = ox, oz, th, w, ax, az

    # backward pass: moments about o_k (inertial moments Izz * alpha vanish with qdd = 0)
    Fx = Fz = 0.0
    M = 0.0
    for k in range(n - 1, -1, -1):
        r = wk[k]
        nx = wk[k + 1]
        px, pz = r[_O], r[_O + 1]
        dx, dz = r[_C] - px, r[_C + 1] - pz
        ex, ez = nx[_O] - px, nx[_O + 1] - pz
        fx, fz = r[_F], r[_F + 1]
        M = (dx * fz - dz * fx) + M + (ex * Fz - ez * Fx)
        Fx += fx
        Fz += fz
        h[k] = M + links[k, COL_VISCOUS] * dq[k]

    # composite rigid bodies about o_i: mass Mc, first moment (hx, hz), inertia Ic
    Mc = 0.0
    hx = hz = 0.0
    Ic = 0.0
    for i in range(n - 1, -1, -1):
        r = wk[i]
        nx = wk[i + 1]
        px, pz = r[_O], r[_O + 1]
        ex, ez = nx[_O] - px, nx[_O + 1] - pz
        Ic += 2.0 * (hx * ex + hz * ez) + Mc * (ex * ex + ez * ez)
        hx += Mc * ex
        hz += Mc * ez
        m = links[i, COL_MASS]
        dx, dz = r[_C] - px, r[_C + 1] - pz
        Ic += links[i, COL_IZZ] + m * (dx * dx + dz * dz)
        hx += m * dx
        hz += m * dz
        Mc += m
        # unit acceleration of joint i: force 1 x h = (-hz, hx)
        Fx, Fz = -hz, hx
        H[i, i] = Ic + links[i, COL_MOTOR]
        for j in range(i - 1, -1, -1):
            rj = wk[j]
            rx, rz = px - rj[_O], pz - rj[_O + 1]
            v = Ic + (rx * Fz - rz * Fx)
            H[j, i] = v
            H[i, j] = v

    # tip
    ct, st = math.cos(th), math.sin(th)
    tx = ox + ct * tool[0] - st * tool[1]
    tz = oz + st * tool[0] + ct * tool[1]
    Y[0], Y[1], Y[2] = tx, tz, th + tool[2]
    for k in range(n):
        r = wk[k]
        J[0, k] = -(tz - r[_O + 1])
        J[1, k] = tx - r[_O]
        J[2, k] = 1.0
    w2 = w * w
    Jdq[0] = ax - w2 * (tx - ox) + gx
    Jdq[1] = az - w2 * (tz - oz) + gz
    Jdq[2] = 0.0
    return 0


@njit(cache=True)
def planar_arm_potential(q, links, base, gravity):
    """Gravitational potential energy ``U = -sum_k m_k g . p_com_k`` [J]."""
    n = q.shape[0]
    ox, oz, th = base[0], base[1], base[2]
    U = 0.0
    for k in range(n):
        th += q[k]
        ct, st = math.cos(th), math.sin(th)
        row = links[k]
        cx = ox + ct * row[COL_RCX] - st * row[COL_RCY]
        cz = oz + st * row[COL_RCX] + ct * row[COL_RCY]
        U -= row[COL_MASS] * (gravity[0] * cx + gravity[1] * cz)
        ox += row[COL_LENGTH] * ct
        oz += row[COL_LENGTH] * st
    return U
