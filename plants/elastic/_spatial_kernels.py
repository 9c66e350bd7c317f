"""numba kernels of the spatial elastic system (docs/model.md s.3, eqs. 104-121).

Kept for the numba code that still calls it: the cooperative numba kernels; ElasticSystem calls the compiled core
(plants/core/elastic_*). It goes with its last caller (tests/test_plants_without_numba.py lists it).

Arrays: ``Y`` and ``dY`` are (N, 6) node poses ``(r, A)`` and their rates; ``node_params`` is
(N, 4) ``(mass, I1, I2, I3)``; ``edge_index`` (E, 4) and ``edge_params`` (E, ``EDGE_WIDTH_SPATIAL``) follow
:mod:`plants.elastic._layout`, whose named columns (``SPRING_*``, ``MATRIX_*``) the kernels read. Forces are *added* into the (N, 6) output arrays so that the
cooperative kernel can accumulate everything in one buffer. Each kernel returns a status code
from :mod:`plants.elastic._layout` instead of raising, so that it can run inside the fused
right-hand side.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.elastic._layout import (
    CHART_OWN,
    CHART_STORED,
    DAMPING_BOOK,
    EDGE_DAMPING_FORM,
    EDGE_KIND,
    EDGE_NODE_I,
    EDGE_NODE_J,
    ELEMENT_CENTRAL,
    ELEMENT_MATRIX,
    MATRIX_C_SPATIAL,
    MATRIX_K,
    MATRIX_LINEAR_SPATIAL,
    MATRIX_M_SPATIAL,
    MATRIX_N_SPATIAL,
    MATRIX_U0_SPATIAL,
    NODE_CHART,
    NODE_CHART_KIND,
    NODE_INERTIA,
    NODE_MASS,
    ROTATION_FORM_COL,
    SPRING_DAMPING,
    SPRING_KAPPA,
    SPRING_REST_ANGLES,
    SPRING_REST_LENGTH,
    SPRING_REST_OFFSET,
    SPRING_REST_ROTATION,
    SPRING_STIFFNESS,
    SPRING_TORSION,
    SPRING_TORSION_DAMPING,
    STATUS_COINCIDENT_NODES,
    STATUS_EULER_SINGULAR,
    STATUS_OK,
)
from plants._numba_frames import rotation_and_partials_from_trig, rotation_zyx_and_partials_into
from plants.frames import EULER_SINGULARITY_COS

#: Nodes of a central spring with positive rest length closer than this fraction of the rest
#: length are reported as coincident: ``beta`` and its gradient are undefined at distance 0.
COINCIDENT_FRACTION = 1e-9

#: Shape of the scratch array of the ``*_into`` edge kernels (3x3 blocks; a block's rows serve as
#: 3-vectors). :func:`elastic_edges_into`: 8 ``P``, 9 ``QR``, 10 the vectors ``d`` and ``C e``;
#: :func:`damping_edges_into`: 11-13 the vectors ``rho``, ``omega``, ``g``, ``w_i``, ``w_j``, ``Wd``,
#: ``h``, ``Hw``, ``Hi``; :func:`node_terms_into`: 15 (``g``, zeros); :func:`matrix_edge` 16-21 and
#: :func:`geodesic_rotation_edge` 16-18 (each on its own); the cooperative plant's
#: ``interconnection_into`` (plants.cooperative._spatial_kernel): 14 and 15.
#: The kernels overwrite what they use; the content between calls means nothing.
EDGE_SCRATCH_SHAPE = (22, 3, 3)
#: 3x3 blocks per node of the ``frames`` array of :func:`node_frames_into`: ``R``, three ``dR/dA``, ``L``,
#: and the node's chart ``C`` (block ``FRAME_CHART``; read only for a node in a chart, see
#: :func:`apply_charts_into`). With a chart, blocks 0-3 hold ``C R(A)`` and ``C dR/dA``.
NODE_FRAME_BLOCKS = 6
FRAME_CHART = 5


@njit(cache=True, inline="always")
def wrap_angle(a):
    """Map an angle difference [rad] into (-pi, pi]."""
    return a - 2.0 * math.pi * math.floor((a + math.pi) / (2.0 * math.pi))


@njit(cache=True, inline="always")
def log_so3_into(Q, out):
    """The rotation vector ``out = log(Q)`` [rad] of the rotation matrix ``Q`` (3x3), and the coefficient
    ``c`` of the inverse right Jacobian ``J_r^-1(out) = I + 1/2 [out]x + c [out]x^2``; returns ``c``.

    .. math::
        \\phi = \\mathrm{atan2}(|v|, \\mathrm{tr}\\,Q - 1), \\quad v = \\mathrm{vee}(Q - Q^T) = 2 \\sin\\phi\\, u,
        \\quad \\log Q = \\phi\\, v / |v|, \\quad c = 1/\\phi^2 - (1 + \\cos\\phi) / (2 \\phi \\sin\\phi)

    with ``cos(phi) = (tr Q - 1) / 2`` and ``sin(phi) = |v| / 2``: one ``atan2``, no other trigonometry
    (series near ``phi = 0``: ``log Q = (1 + phi^2 / 6) v / 2``, ``c = 1/12 + phi^2/720 + phi^4/30240``).
    Exact up to a relative rotation near ``pi``, where ``log`` is not unique."""
    v0 = Q[2, 1] - Q[1, 2]
    v1 = Q[0, 2] - Q[2, 0]
    v2 = Q[1, 0] - Q[0, 1]
    sv = math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)  # 2 sin(phi)
    tr1 = Q[0, 0] + Q[1, 1] + Q[2, 2] - 1.0  # 2 cos(phi)
    ang = math.atan2(sv, tr1)
    fac = 0.5 * (1.0 + ang * ang / 6.0) if ang < 1e-4 else ang / sv
    out[0] = fac * v0
    out[1] = fac * v1
    out[2] = fac * v2
    a2 = ang * ang
    if ang < 1e-3:
        return 1.0 / 12.0 + a2 / 720.0 + a2 * a2 / 30240.0
    return 1.0 / a2 - (1.0 + 0.5 * tr1) / (ang * sv)  # (1 + cos phi) / (2 phi sin phi), no trigonometry


@njit(cache=True, _nrt=False)
def matrix_edge(Y, dY, i, j, p, F, scratch, frames, rates):
    """One matrix element (co-rotational; docs/model.md s.3 [ours]) between nodes i and j.

    The element frame turns with node i, ``R_e = R_i M``; node j's deformation in it is

    .. math::
        u = R_e^T (r_j - r_i) - u_0, \\quad \\theta = \\log(R_e^T R_j N), \\qquad
        \\Pi = \\tfrac12 d^T K_{jj} d, \\quad d = (u, \\theta),

    ``M = R_i0^T R_e0``, ``N = R_j0^T R_e0`` (rest frames), ``K_jj`` the element stiffness with
    node i clamped. With ``g = K_jj d`` and ``h = J_r^{-T}(theta) g_theta`` (``J_r`` the right
    Jacobian of SO(3)), the generalized forces are ``dPi/dr_j = R_e g_u = -dPi/dr_i``,
    ``dPi/dA_i = L_i^T M (g_u x p - Q h)`` (``p = R_e^T (r_j - r_i)``, ``Q = R_e^T R_j N``) and
    ``dPi/dA_j = L_j^T N h``. ``rates=True`` gives the dampers instead: ``d_dot = G v`` (``v`` the
    velocities and body angular velocities ``omega = L dA``, ``G`` the same Jacobian), ``D = 1/2
    d_dot^T C_jj d_dot``, generalized forces ``G^T C_jj d_dot`` by the same formulas with ``g =
    C_jj d_dot``. Both are invariant under rigid motions of the pair. Returns ``Pi`` (or ``D``).
    """
    Ri = frames[i, 0]
    Rj = frames[j, 0]
    Li = frames[i, 4]
    Lj = frames[j, 4]
    Re = scratch[16]
    Q = scratch[17]
    vec = scratch[18]   # rows: p, theta, g_u
    vec2 = scratch[19]  # rows: g_theta, h, x (work)
    for a in range(3):
        for b in range(3):
            Re[a, b] = (Ri[a, 0] * p[MATRIX_M_SPATIAL + b] + Ri[a, 1] * p[MATRIX_M_SPATIAL + 3 + b]
                        + Ri[a, 2] * p[MATRIX_M_SPATIAL + 6 + b])
    for a in range(3):
        for b in range(3):
            acc = 0.0
            for k in range(3):
                acc += Re[k, a] * (Rj[k, 0] * p[MATRIX_N_SPATIAL + b] + Rj[k, 1] * p[MATRIX_N_SPATIAL + 3 + b]
                                   + Rj[k, 2] * p[MATRIX_N_SPATIAL + 6 + b])
            Q[a, b] = acc
    pv = vec[0]
    th = vec[1]
    for a in range(3):
        pv[a] = (Re[0, a] * (Y[j, 0] - Y[i, 0]) + Re[1, a] * (Y[j, 1] - Y[i, 1])
                 + Re[2, a] * (Y[j, 2] - Y[i, 2]))
    c = log_so3_into(Q, th)  # theta = log(Q); J_r^-1 = I + 1/2 [th]x + c [th]x^2
    d = vec2[2]
    x = scratch[20][0]
    if rates:
        # omega_i in the element frame: M^T L_i dA_i; omega_j: N^T L_j dA_j
        wi = scratch[20][1]
        wj = scratch[20][2]
        for a in range(3):
            oi0 = Li[0, 0] * dY[i, 3] + Li[0, 1] * dY[i, 4] + Li[0, 2] * dY[i, 5]
            oi1 = Li[1, 0] * dY[i, 3] + Li[1, 1] * dY[i, 4] + Li[1, 2] * dY[i, 5]
            oi2 = Li[2, 0] * dY[i, 3] + Li[2, 1] * dY[i, 4] + Li[2, 2] * dY[i, 5]
            oj0 = Lj[0, 0] * dY[j, 3] + Lj[0, 1] * dY[j, 4] + Lj[0, 2] * dY[j, 5]
            oj1 = Lj[1, 0] * dY[j, 3] + Lj[1, 1] * dY[j, 4] + Lj[1, 2] * dY[j, 5]
            oj2 = Lj[2, 0] * dY[j, 3] + Lj[2, 1] * dY[j, 4] + Lj[2, 2] * dY[j, 5]
            wi[a] = p[MATRIX_M_SPATIAL + a] * oi0 + p[MATRIX_M_SPATIAL + 3 + a] * oi1 + p[MATRIX_M_SPATIAL + 6 + a] * oi2
            wj[a] = p[MATRIX_N_SPATIAL + a] * oj0 + p[MATRIX_N_SPATIAL + 3 + a] * oj1 + p[MATRIX_N_SPATIAL + 6 + a] * oj2
        # u_dot = R_e^T (dr_j - dr_i) + p x w_i
        du = scratch[21][0]
        for a in range(3):
            du[a] = (Re[0, a] * (dY[j, 0] - dY[i, 0]) + Re[1, a] * (dY[j, 1] - dY[i, 1])
                     + Re[2, a] * (dY[j, 2] - dY[i, 2]))
        du[0] += pv[1] * wi[2] - pv[2] * wi[1]
        du[1] += pv[2] * wi[0] - pv[0] * wi[2]
        du[2] += pv[0] * wi[1] - pv[1] * wi[0]
        # theta_dot = J_r^-1 (w_j - Q^T w_i)
        for a in range(3):
            x[a] = wj[a] - (Q[0, a] * wi[0] + Q[1, a] * wi[1] + Q[2, a] * wi[2])
        t0 = th[1] * x[2] - th[2] * x[1]
        t1 = th[2] * x[0] - th[0] * x[2]
        t2 = th[0] * x[1] - th[1] * x[0]
        s0 = th[1] * t2 - th[2] * t1
        s1 = th[2] * t0 - th[0] * t2
        s2 = th[0] * t1 - th[1] * t0
        dd = scratch[21][1]
        dd[0] = du[0]
        dd[1] = du[1]
        dd[2] = du[2]
        dth = scratch[21][2]
        dth[0] = x[0] + 0.5 * t0 + c * s0
        dth[1] = x[1] + 0.5 * t1 + c * s1
        dth[2] = x[2] + 0.5 * t2 + c * s2
        base = MATRIX_C_SPATIAL
    else:
        dd = scratch[21][1]
        dth = scratch[21][2]
        for a in range(3):
            dd[a] = pv[a] - p[MATRIX_U0_SPATIAL + a]
            dth[a] = th[a]
        base = MATRIX_K
    gu = vec[2]
    gt = vec2[0]
    E = 0.0
    for a in range(3):
        su = 0.0
        st = 0.0
        for b in range(3):
            su += p[base + 6 * a + b] * dd[b] + p[base + 6 * a + 3 + b] * dth[b]
            st += p[base + 6 * (3 + a) + b] * dd[b] + p[base + 6 * (3 + a) + 3 + b] * dth[b]
        gu[a] = su
        gt[a] = st
        E += 0.5 * (dd[a] * su + dth[a] * st)
    # h = J_r^-T g_theta = g - 1/2 th x g + c th x (th x g)
    t0 = th[1] * gt[2] - th[2] * gt[1]
    t1 = th[2] * gt[0] - th[0] * gt[2]
    t2 = th[0] * gt[1] - th[1] * gt[0]
    h = vec2[1]
    h[0] = gt[0] - 0.5 * t0 + c * (th[1] * t2 - th[2] * t1)
    h[1] = gt[1] - 0.5 * t1 + c * (th[2] * t0 - th[0] * t2)
    h[2] = gt[2] - 0.5 * t2 + c * (th[0] * t1 - th[1] * t0)
    for a in range(3):
        f = Re[a, 0] * gu[0] + Re[a, 1] * gu[1] + Re[a, 2] * gu[2]
        F[j, a] += f
        F[i, a] -= f
    # tau_e = g_u x p - Q h (element frame), tau_i = M tau_e, tau_j = N h
    d[0] = gu[1] * pv[2] - gu[2] * pv[1] - (Q[0, 0] * h[0] + Q[0, 1] * h[1] + Q[0, 2] * h[2])
    d[1] = gu[2] * pv[0] - gu[0] * pv[2] - (Q[1, 0] * h[0] + Q[1, 1] * h[1] + Q[1, 2] * h[2])
    d[2] = gu[0] * pv[1] - gu[1] * pv[0] - (Q[2, 0] * h[0] + Q[2, 1] * h[1] + Q[2, 2] * h[2])
    for a in range(3):
        x[a] = p[MATRIX_M_SPATIAL + 3 * a] * d[0] + p[MATRIX_M_SPATIAL + 1 + 3 * a] * d[1] + p[MATRIX_M_SPATIAL + 2 + 3 * a] * d[2]
    for a in range(3):
        F[i, 3 + a] += Li[0, a] * x[0] + Li[1, a] * x[1] + Li[2, a] * x[2]
    for a in range(3):
        x[a] = p[MATRIX_N_SPATIAL + 3 * a] * h[0] + p[MATRIX_N_SPATIAL + 1 + 3 * a] * h[1] + p[MATRIX_N_SPATIAL + 2 + 3 * a] * h[2]
    for a in range(3):
        F[j, 3 + a] += Lj[0, a] * x[0] + Lj[1, a] * x[1] + Lj[2, a] * x[2]
    return E


@njit(cache=True, _nrt=False)
def geodesic_rotation_edge(i, j, p, F, scratch, frames):
    """The geodesic rotation spring of a central or offset edge (rotation form ``ROTATION_GEODESIC``,
    docs/model.md s.3 [ours]); adds its generalized forces into ``F`` and returns its energy.

    .. math::
        \\Delta = R_i^T R_j R_0^T, \\quad e = \\log(\\Delta), \\quad
        \\Pi = \\tfrac12 e^T C_A e, \\quad C_A = \\mathrm{diag}(cA_\\phi, cA_\\theta, cA_\\psi)

    ``R_0`` the rest relative rotation ``R_i0^T R_j0`` (columns 18-26 of ``p``), ``e`` [rad] the
    rotation vector of node j against its rest rotation, in node i's frame (axes x, y, z: the book's
    ``cA`` per ``(psi, theta, phi)`` are about z, y, x at ``A = 0``, hence the reversed order). With
    body-frame variations ``R_k -> R_k exp([da_k])``, ``de = J_r^-1(e) (R_0 da_j - Delta^T da_i)``
    (``J_r`` the right Jacobian of SO(3)), so with ``g = C_A e`` and ``h = J_r^-T g``:

    .. math::
        \\tau_j = R_0^T h, \\quad \\tau_i = -\\Delta h, \\qquad
        \\partial \\Pi / \\partial A_k = L_k^T \\tau_k

    (body torques ``tau_k`` [N m] mapped to the angles of node k's chart by ``L_k``). It depends on
    the rotations only, so on no chart; it is invariant under rigid motions of the pair (4.7).
    """
    Ri = frames[i, 0]
    Rj = frames[j, 0]
    Li = frames[i, 4]
    Lj = frames[j, 4]
    P = scratch[16]
    Dl = scratch[17]
    vec = scratch[18]  # rows: e, h, torque
    for l in range(3):
        for k in range(3):
            P[l, k] = (Rj[l, 0] * p[SPRING_REST_ROTATION + 3 * k] + Rj[l, 1] * p[SPRING_REST_ROTATION + 1 + 3 * k]
                       + Rj[l, 2] * p[SPRING_REST_ROTATION + 2 + 3 * k])
    for a in range(3):
        for b in range(3):
            Dl[a, b] = Ri[0, a] * P[0, b] + Ri[1, a] * P[1, b] + Ri[2, a] * P[2, b]
    e = vec[0]
    c = log_so3_into(Dl, e)  # e = log(Delta); J_r^-1 = I + 1/2 [e]x + c [e]x^2
    g0 = p[SPRING_TORSION + 2] * e[0]
    g1 = p[SPRING_TORSION + 1] * e[1]
    g2 = p[SPRING_TORSION] * e[2]
    E = 0.5 * (e[0] * g0 + e[1] * g1 + e[2] * g2)
    # h = J_r^-T g = g - 1/2 e x g + c e x (e x g)
    t0 = e[1] * g2 - e[2] * g1
    t1 = e[2] * g0 - e[0] * g2
    t2 = e[0] * g1 - e[1] * g0
    h = vec[1]
    h[0] = g0 - 0.5 * t0 + c * (e[1] * t2 - e[2] * t1)
    h[1] = g1 - 0.5 * t1 + c * (e[2] * t0 - e[0] * t2)
    h[2] = g2 - 0.5 * t2 + c * (e[0] * t1 - e[1] * t0)
    tq = vec[2]
    for a in range(3):  # tau_j = R_0^T h
        tq[a] = (p[SPRING_REST_ROTATION + a] * h[0] + p[SPRING_REST_ROTATION + 3 + a] * h[1]
                 + p[SPRING_REST_ROTATION + 6 + a] * h[2])
    for a in range(3):
        F[j, 3 + a] += Lj[0, a] * tq[0] + Lj[1, a] * tq[1] + Lj[2, a] * tq[2]
    for a in range(3):  # tau_i = -Delta h
        tq[a] = -(Dl[a, 0] * h[0] + Dl[a, 1] * h[1] + Dl[a, 2] * h[2])
    for a in range(3):
        F[i, 3 + a] += Li[0, a] * tq[0] + Li[1, a] * tq[1] + Li[2, a] * tq[2]
    return E


@njit(cache=True, _nrt=False)
def linear_matrix_edge(Y, dY, Y_ref, i, j, p, F, col, n, angles_from):
    """The matrix element in the immobile model (4.5): with ``y = (Y_i - Y_ref_i, Y_j - Y_ref_j)``
    (angles from coordinate ``angles_from`` on wrapped), add ``K_lin y + D_lin dy`` into ``F``
    and return ``Pi = 1/2 y^T K_lin y``. ``K_lin = G0^T K_jj G0`` and ``D_lin = G0^T C_jj G0``
    (2n x 2n, row-major at columns ``col`` and ``col + 4 n^2`` of ``p``) are the linearization of
    :func:`matrix_edge` at the reference poses, packed once."""
    m = 2 * n
    E = 0.0
    for a in range(m):
        na = i if a < n else j
        ka = a % n
        fa = 0.0
        ya = Y[na, ka] - Y_ref[na, ka]
        if ka >= angles_from:
            ya = wrap_angle(ya)
        for b in range(m):
            nb = i if b < n else j
            kb = b % n
            yb = Y[nb, kb] - Y_ref[nb, kb]
            if kb >= angles_from:
                yb = wrap_angle(yb)
            fa += p[col + a * m + b] * yb + p[col + m * m + a * m + b] * dY[nb, kb]
            E += 0.5 * ya * p[col + a * m + b] * yb
        F[na, ka] += fa
    return E

@njit(cache=True)
def node_frames_charted(Y, node_params):
    """:func:`node_frames_charted_into` into a new (N, NODE_FRAME_BLOCKS, 3, 3) array."""
    frames = np.zeros((Y.shape[0], NODE_FRAME_BLOCKS, 3, 3))
    node_frames_charted_into(Y, node_params, frames)
    return frames


@njit(cache=True)
def elastic_edges_framed(Y, edge_index, edge_params, F, frames):
    """:func:`elastic_edges_into` with scratch of its own, on the caller's ``frames`` (charted nodes)."""
    return elastic_edges_into(Y, edge_index, edge_params, F, np.empty(EDGE_SCRATCH_SHAPE), frames)


@njit(cache=True)
def damping_edges_framed(Y, dY, edge_index, edge_params, F, frames):
    """:func:`damping_edges_into` with scratch of its own, on the caller's ``frames`` (charted nodes)."""
    return damping_edges_into(Y, dY, edge_index, edge_params, F, np.empty(EDGE_SCRATCH_SHAPE), frames)


@njit(cache=True)
def elastic_edges(Y, edge_index, edge_params, F):
    """:func:`elastic_edges_into` with scratch and node frames of its own (allocated per call)."""
    frames = np.empty((Y.shape[0], NODE_FRAME_BLOCKS, 3, 3))
    node_frames_into(Y, frames)
    return elastic_edges_into(Y, edge_index, edge_params, F, np.empty(EDGE_SCRATCH_SHAPE), frames)


@njit(cache=True, _nrt=False)
def elastic_edges_into(Y, edge_index, edge_params, F, scratch, frames):
    """Add ``dPi/dY`` (120-121) of every interconnection into ``F``; return ``(Pi, status)``.

    Allocates nothing: ``scratch`` is a float64 array of shape ``EDGE_SCRATCH_SHAPE`` (overwritten);
    ``frames`` (N, NODE_FRAME_BLOCKS, 3, 3) holds every node's ``R``, ``dR/dA`` (from :func:`node_frames_into`).

    Central element (106-107, 119), ``d = r_i - r_j``, ``s = |d|``, ``g = 1 - l/s``,
    ``beta = g^2``, ``Q = sum_k c_k d_k^2``:

    .. math::
        \\Pi = \\tfrac12 \\beta Q + \\tfrac12 \\sum_k cA_k \\delta_k^2, \\quad
        \\delta = A_i - A_j - A0, \\quad
        \\partial \\Pi / \\partial r_i = g l Q d / s^3 + g^2 C d

    (the first term is the derivative of ``beta``; ``delta`` is wrapped into (-pi, pi]).

    Offset element (ours): ``e = R_i^T (r_j - r_i) - rho`` in node i's frame and
    ``Pi = 1/2 e^T C e + sum_k kappa_k (1 - M_kk)``, ``M = R_i^T R_j R0^T``: rotation invariant,
    with small-angle torsion stiffness ``cA_l = sum_{k != l} kappa_k``.

    Rotation form ``ROTATION_GEODESIC`` (column ``ROTATION_FORM_COL`` of an edge row; central and
    offset elements): the rotational term is :func:`geodesic_rotation_edge`, ``1/2 e^T C_A e`` on the
    relative rotation vector, in place of the Euler difference (central) or of ``kappa`` (offset).
    ``frames`` holds the nodes' world rotations ``C R(A)`` whatever their charts, so every term but the
    book's Euler difference is right in any chart.
    """
    Pi = 0.0
    for e in range(edge_index.shape[0]):
        i = edge_index[e, EDGE_NODE_I]
        j = edge_index[e, EDGE_NODE_J]
        p = edge_params[e]
        if edge_index[e, EDGE_KIND] == ELEMENT_CENTRAL:
            d0 = Y[i, 0] - Y[j, 0]
            d1 = Y[i, 1] - Y[j, 1]
            d2 = Y[i, 2] - Y[j, 2]
            Q = p[SPRING_STIFFNESS] * d0 * d0 + p[SPRING_STIFFNESS + 1] * d1 * d1 + p[SPRING_STIFFNESS + 2] * d2 * d2
            l = p[SPRING_REST_LENGTH]
            if l > 0.0:
                s = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
                if s < COINCIDENT_FRACTION * l:
                    return Pi, STATUS_COINCIDENT_NODES
                g = 1.0 - l / s
                a = g * l * Q / (s * s * s)
                g2 = g * g
            else:
                a = 0.0
                g2 = 1.0
            Pi += 0.5 * g2 * Q
            f0 = a * d0 + g2 * p[SPRING_STIFFNESS] * d0
            f1 = a * d1 + g2 * p[SPRING_STIFFNESS + 1] * d1
            f2 = a * d2 + g2 * p[SPRING_STIFFNESS + 2] * d2
            F[i, 0] += f0
            F[i, 1] += f1
            F[i, 2] += f2
            F[j, 0] -= f0
            F[j, 1] -= f1
            F[j, 2] -= f2
            if p[ROTATION_FORM_COL] != 0.0:
                if p[SPRING_TORSION] != 0.0 or p[SPRING_TORSION + 1] != 0.0 or p[SPRING_TORSION + 2] != 0.0:
                    Pi += geodesic_rotation_edge(i, j, p, F, scratch, frames)
                continue
            for k in range(3):
                cA = p[SPRING_TORSION + k]
                if cA != 0.0:
                    dl = wrap_angle(Y[i, 3 + k] - Y[j, 3 + k] - p[SPRING_REST_ANGLES + k])
                    Pi += 0.5 * cA * dl * dl
                    F[i, 3 + k] += cA * dl
                    F[j, 3 + k] -= cA * dl
        elif edge_index[e, EDGE_KIND] == ELEMENT_MATRIX:
            Pi += matrix_edge(Y, Y, i, j, p, F, scratch, frames, False)
        else:
            Ri = frames[i, 0]
            dRi = frames[i, 1:4]
            d = scratch[10, 0]
            for k in range(3):
                d[k] = Y[j, k] - Y[i, k]
            Ce = scratch[10, 1]
            for k in range(3):
                ek = Ri[0, k] * d[0] + Ri[1, k] * d[1] + Ri[2, k] * d[2] - p[SPRING_REST_OFFSET + k]
                Pi += 0.5 * p[SPRING_STIFFNESS + k] * ek * ek
                Ce[k] = p[SPRING_STIFFNESS + k] * ek
            for l in range(3):
                f = Ri[l, 0] * Ce[0] + Ri[l, 1] * Ce[1] + Ri[l, 2] * Ce[2]
                F[j, l] += f
                F[i, l] -= f
            for a in range(3):
                acc = 0.0
                for k in range(3):
                    for l in range(3):
                        acc += Ce[k] * dRi[a][l, k] * d[l]
                F[i, 3 + a] += acc
            if p[ROTATION_FORM_COL] != 0.0:
                if p[SPRING_TORSION] != 0.0 or p[SPRING_TORSION + 1] != 0.0 or p[SPRING_TORSION + 2] != 0.0:
                    Pi += geodesic_rotation_edge(i, j, p, F, scratch, frames)
            elif p[SPRING_KAPPA] != 0.0 or p[SPRING_KAPPA + 1] != 0.0 or p[SPRING_KAPPA + 2] != 0.0:
                Rj = frames[j, 0]
                dRj = frames[j, 1:4]
                # P = R_j R0^T ; QR = (R_i Kd) R0 (every entry written below)
                P = scratch[8]
                QR = scratch[9]
                for l in range(3):
                    for k in range(3):
                        s1 = 0.0
                        s2 = 0.0
                        for n in range(3):
                            s1 += Rj[l, n] * p[SPRING_REST_ROTATION + 3 * k + n]
                            s2 += Ri[l, n] * p[SPRING_KAPPA + n] * p[SPRING_REST_ROTATION + 3 * n + k]
                        P[l, k] = s1
                        QR[l, k] = s2
                for k in range(3):
                    Mkk = Ri[0, k] * P[0, k] + Ri[1, k] * P[1, k] + Ri[2, k] * P[2, k]
                    Pi += p[SPRING_KAPPA + k] * (1.0 - Mkk)
                for a in range(3):
                    gi = 0.0
                    gj = 0.0
                    for l in range(3):
                        for k in range(3):
                            gi += p[SPRING_KAPPA + k] * dRi[a][l, k] * P[l, k]
                            gj += dRj[a][l, k] * QR[l, k]
                    F[i, 3 + a] -= gi
                    F[j, 3 + a] -= gj
    return Pi, STATUS_OK


@njit(cache=True, inline="always")
def body_rate_matrix(A, L):
    """``L(A)`` of ``omega = L(A) A_dot`` (body-frame angular velocity from ZYX Euler rates) into ``L`` (3x3)."""
    cth, sth = math.cos(A[1]), math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    L[0, 0], L[0, 1], L[0, 2] = -sth, 0.0, 1.0
    L[1, 0], L[1, 1], L[1, 2] = sph * cth, cph, 0.0
    L[2, 0], L[2, 1], L[2, 2] = cph * cth, -sph, 0.0


@njit(cache=True, _nrt=False)
def node_frames_into(Y, frames):
    """Every node k's ``R(A_k)`` (block 0), ``dR/dpsi, dR/dtheta, dR/dphi`` (1-3) and ``L(A_k)`` (4)
    into ``frames`` (N, NODE_FRAME_BLOCKS, 3, 3): evaluated once per node rather than once per edge end."""
    for k in range(Y.shape[0]):
        rotation_zyx_and_partials_into(Y[k, 3:6], frames[k, 0], frames[k, 1:4])
        body_rate_matrix(Y[k, 3:6], frames[k, 4])


@njit(cache=True, inline="always")
def _left_multiply(C, M):
    """``M <- C M`` in place (3x3), column by column."""
    for b in range(3):
        m0, m1, m2 = M[0, b], M[1, b], M[2, b]
        M[0, b] = C[0, 0] * m0 + C[0, 1] * m1 + C[0, 2] * m2
        M[1, b] = C[1, 0] * m0 + C[1, 1] * m1 + C[1, 2] * m2
        M[2, b] = C[2, 0] * m0 + C[2, 1] * m1 + C[2, 2] * m2


@njit(cache=True, _nrt=False)
def apply_charts_into(node_params, frames):
    """Turn every charted node's frames into its world frames: ``R = C R(A)``, ``dR/dA = C dR(A)/dA``
    (blocks 0-3; ``L`` is the same in every chart, docs/model.md s.2). ``node_params`` rows of
    ``NODE_WIDTH_CHARTED`` columns: kind ``CHART_STORED`` takes ``C`` from the row (and copies it into
    block ``FRAME_CHART``), ``CHART_OWN`` from block ``FRAME_CHART`` (written by the arm kernel),
    ``CHART_WORLD`` is left alone. Allocates nothing."""
    for k in range(frames.shape[0]):
        kind = node_params[k, NODE_CHART_KIND]
        if kind == CHART_STORED:
            C = frames[k, FRAME_CHART]
            for a in range(3):
                for b in range(3):
                    C[a, b] = node_params[k, NODE_CHART + 3 * a + b]
        elif kind != CHART_OWN:
            continue
        C = frames[k, FRAME_CHART]
        for blk in range(4):
            _left_multiply(C, frames[k, blk])


@njit(cache=True, _nrt=False)
def node_frames_charted_into(Y, node_params, frames):
    """:func:`node_frames_into` then, for rows wider than ``NODE_CHART_KIND``, :func:`apply_charts_into`."""
    node_frames_into(Y, frames)
    if node_params.shape[1] > NODE_CHART_KIND:
        apply_charts_into(node_params, frames)


@njit(cache=True, _nrt=False)
def node_frames_terms_into(Y, dY, node_params, gravity, frames, Wr, w):
    """:func:`node_frames_into` and :func:`node_terms_into` of the mobile model (``immobile`` False) in
    one pass, with one evaluation of each node's six sines and cosines (instead of 14): ``frames``
    (N, NODE_FRAME_BLOCKS, 3, 3) receives ``R``, ``dR/dA``, ``L``; ``Wr`` (N, 3, 3) the rotational
    inertia blocks; ``w`` (N, 6) is set to ``(-m g, gyroscopic)``. The same arithmetic as those two
    kernels, so the same bits. Rows of ``node_params`` wider than ``NODE_CHART_KIND`` carry charts:
    then :func:`apply_charts_into` follows (the inertia and gyroscopic terms depend on no chart).
    Allocates nothing."""
    for k in range(Y.shape[0]):
        cps, sps = math.cos(Y[k, 3]), math.sin(Y[k, 3])
        cth, sth = math.cos(Y[k, 4]), math.sin(Y[k, 4])
        cph, sph = math.cos(Y[k, 5]), math.sin(Y[k, 5])
        rotation_and_partials_from_trig(cps, sps, cth, sth, cph, sph, frames[k, 0], frames[k, 1], frames[k, 2],
                                        frames[k, 3])
        L = frames[k, 4]
        L[0, 0], L[0, 1], L[0, 2] = -sth, 0.0, 1.0
        L[1, 0], L[1, 1], L[1, 2] = sph * cth, cph, 0.0
        L[2, 0], L[2, 1], L[2, 2] = cph * cth, -sph, 0.0
        m = node_params[k, NODE_MASS]
        for a in range(3):
            w[k, a] = -m * gravity[a]
        _rotational_terms_from_trig(cth, sth, cph, sph, dY[k, 3:6], node_params[k, NODE_INERTIA:NODE_INERTIA + 3], Wr[k], w[k, 3:6])
    if node_params.shape[1] > NODE_CHART_KIND:
        apply_charts_into(node_params, frames)


@njit(cache=True)
def damping_edges(Y, dY, edge_index, edge_params, F):
    """:func:`damping_edges_into` with scratch and node frames of its own (allocated per call)."""
    frames = np.empty((Y.shape[0], NODE_FRAME_BLOCKS, 3, 3))
    node_frames_into(Y, frames)
    return damping_edges_into(Y, dY, edge_index, edge_params, F, np.empty(EDGE_SCRATCH_SHAPE), frames)


@njit(cache=True, _nrt=False)
def damping_edges_into(Y, dY, edge_index, edge_params, F, scratch, frames):
    """Add ``dD/d(dY)`` of the dampers (110-111) into ``F``; return the Rayleigh function ``D`` [W/2].

    Allocates nothing: ``scratch`` is a float64 array of shape ``EDGE_SCRATCH_SHAPE`` (overwritten);
    ``frames`` (N, NODE_FRAME_BLOCKS, 3, 3) holds every node's ``R``, ``dR/dA`` (from :func:`node_frames_into`).

    Central element, translation: ``D = 1/2 d (u^T (dr_i - dr_j))^2``, ``u = (r_i - r_j)/|r_i - r_j|``
    (the book's, frame invariant). Frame-invariant form (damping form ``DAMPING_FRAME_INVARIANT``,
    docs/model.md s.3 [ours]), with ``omega_k = L(A_k) dA_k`` in node k's frame:

    .. math::
        \\dot e = R_i^T (\\dot r_j - \\dot r_i) + \\rho \\times \\omega_i, \\quad
        \\rho = R_i^T (r_j - r_i), \\qquad
        \\omega_{rel} = L_j \\dot A_j - R_j^T R_i L_i \\dot A_i,

        D = \\tfrac12 d |\\dot e|^2 \\;(\\text{offset}) + \\tfrac12 dA |\\omega_{rel}|^2,

    both zero under any rigid motion of the pair; the generalized forces are
    ``(d e_dot/d Y_dot)^T d e_dot + (d omega_rel/d Y_dot)^T dA omega_rel``. The book's form
    (``DAMPING_BOOK``): offset ``D = 1/2 d |dr_i - dr_j|^2`` and torsion
    ``D = 1/2 dA |dA_i - dA_j|^2`` on the Euler rates.
    """
    D = 0.0
    for e in range(edge_index.shape[0]):
        i = edge_index[e, EDGE_NODE_I]
        j = edge_index[e, EDGE_NODE_J]
        p = edge_params[e]
        if edge_index[e, EDGE_KIND] == ELEMENT_MATRIX:
            D += matrix_edge(Y, dY, i, j, p, F, scratch, frames, True)
            continue
        book = edge_index[e, EDGE_DAMPING_FORM] == DAMPING_BOOK
        central = edge_index[e, EDGE_KIND] == ELEMENT_CENTRAL
        dd = p[SPRING_DAMPING]
        dA = p[SPRING_TORSION_DAMPING]
        Ri = frames[i, 0]
        Li = frames[i, 4]
        if dd != 0.0:
            v0 = dY[i, 0] - dY[j, 0]
            v1 = dY[i, 1] - dY[j, 1]
            v2 = dY[i, 2] - dY[j, 2]
            d0 = Y[i, 0] - Y[j, 0]
            d1 = Y[i, 1] - Y[j, 1]
            d2 = Y[i, 2] - Y[j, 2]
            s = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            if central and s > 1e-12:
                vu = (v0 * d0 + v1 * d1 + v2 * d2) / s
                D += 0.5 * dd * vu * vu
                f = dd * vu / s
                f0, f1, f2 = f * d0, f * d1, f * d2
            elif central or book:
                D += 0.5 * dd * (v0 * v0 + v1 * v1 + v2 * v2)
                f0, f1, f2 = dd * v0, dd * v1, dd * v2
            else:
                # rho = R_i^T (r_j - r_i), omega_i = L_i dA_i, e_dot = R_i^T (dr_j - dr_i) + rho x omega_i
                rho = scratch[11, 0]
                om = scratch[11, 1]
                for k in range(3):
                    rho[k] = -(Ri[0, k] * d0 + Ri[1, k] * d1 + Ri[2, k] * d2)
                    om[k] = Li[k, 0] * dY[i, 3] + Li[k, 1] * dY[i, 4] + Li[k, 2] * dY[i, 5]
                g = scratch[11, 2]
                for k in range(3):
                    g[k] = -(Ri[0, k] * v0 + Ri[1, k] * v1 + Ri[2, k] * v2)
                g[0] += rho[1] * om[2] - rho[2] * om[1]
                g[1] += rho[2] * om[0] - rho[0] * om[2]
                g[2] += rho[0] * om[1] - rho[1] * om[0]
                D += 0.5 * dd * (g[0] * g[0] + g[1] * g[1] + g[2] * g[2])
                for k in range(3):
                    g[k] *= dd
                # force on node i: -(R_i g); on node j: +R_i g (applied below with the opposite sign)
                f0 = -(Ri[0, 0] * g[0] + Ri[0, 1] * g[1] + Ri[0, 2] * g[2])
                f1 = -(Ri[1, 0] * g[0] + Ri[1, 1] * g[1] + Ri[1, 2] * g[2])
                f2 = -(Ri[2, 0] * g[0] + Ri[2, 1] * g[1] + Ri[2, 2] * g[2])
                # d(rho x omega)/d omega = S(rho): generalized force L_i^T S(rho)^T g = L_i^T (g x rho)
                c0 = g[1] * rho[2] - g[2] * rho[1]
                c1 = g[2] * rho[0] - g[0] * rho[2]
                c2 = g[0] * rho[1] - g[1] * rho[0]
                for a in range(3):
                    F[i, 3 + a] += Li[0, a] * c0 + Li[1, a] * c1 + Li[2, a] * c2
            F[i, 0] += f0
            F[i, 1] += f1
            F[i, 2] += f2
            F[j, 0] -= f0
            F[j, 1] -= f1
            F[j, 2] -= f2
        if dA != 0.0:
            if book:
                for k in range(3):
                    v = dY[i, 3 + k] - dY[j, 3 + k]
                    D += 0.5 * dA * v * v
                    F[i, 3 + k] += dA * v
                    F[j, 3 + k] -= dA * v
            else:
                Rj = frames[j, 0]
                Lj = frames[j, 4]
                # world angular velocities, their difference in node j's frame
                wi = scratch[12, 0]
                wj = scratch[12, 1]
                for k in range(3):
                    wi[k] = Li[k, 0] * dY[i, 3] + Li[k, 1] * dY[i, 4] + Li[k, 2] * dY[i, 5]
                    wj[k] = Lj[k, 0] * dY[j, 3] + Lj[k, 1] * dY[j, 4] + Lj[k, 2] * dY[j, 5]
                Wd = scratch[12, 2]
                for l in range(3):
                    Wd[l] = (Rj[l, 0] * wj[0] + Rj[l, 1] * wj[1] + Rj[l, 2] * wj[2]
                             - Ri[l, 0] * wi[0] - Ri[l, 1] * wi[1] - Ri[l, 2] * wi[2])
                h = scratch[13, 0]  # dA * omega_rel, omega_rel = R_j^T (omega_j^w - omega_i^w)
                for k in range(3):
                    h[k] = Rj[0, k] * Wd[0] + Rj[1, k] * Wd[1] + Rj[2, k] * Wd[2]
                    D += 0.5 * dA * h[k] * h[k]
                for k in range(3):
                    h[k] *= dA
                # node j: L_j^T h; node i: -L_i^T R_i^T R_j h
                Hw = scratch[13, 1]
                for l in range(3):
                    Hw[l] = Rj[l, 0] * h[0] + Rj[l, 1] * h[1] + Rj[l, 2] * h[2]
                Hi = scratch[13, 2]
                for k in range(3):
                    Hi[k] = Ri[0, k] * Hw[0] + Ri[1, k] * Hw[1] + Ri[2, k] * Hw[2]
                for a in range(3):
                    F[j, 3 + a] += Lj[0, a] * h[0] + Lj[1, a] * h[1] + Lj[2, a] * h[2]
                    F[i, 3 + a] -= Li[0, a] * Hi[0] + Li[1, a] * Hi[1] + Li[2, a] * Hi[2]
    return D


@njit(cache=True, _nrt=False)
def linear_edges(Y, dY, Y_ref, edge_index, edge_params, F):
    """Immobile unloaded state (4.5): add ``K y + D dy`` per edge into ``F``; return ``Pi``.

    ``y = Y - Y_ref`` (angles wrapped), vector springs ``K_ij = diag(c, cA)`` and dampers
    ``D_ij = diag(d I3, dA I3)`` assembled like a graph Laplacian (95-102).
    """
    Pi = 0.0
    for e in range(edge_index.shape[0]):
        i = edge_index[e, EDGE_NODE_I]
        j = edge_index[e, EDGE_NODE_J]
        p = edge_params[e]
        if edge_index[e, EDGE_KIND] == ELEMENT_MATRIX:
            Pi += linear_matrix_edge(Y, dY, Y_ref, i, j, p, F, MATRIX_LINEAR_SPATIAL, 6, 3)
            continue
        for k in range(6):
            diff = (Y[i, k] - Y_ref[i, k]) - (Y[j, k] - Y_ref[j, k])
            if k >= 3:
                kk = p[SPRING_TORSION + k - 3]
                diff = wrap_angle(diff)  # a common rotation is a zero mode, also across +-pi
                dk = p[SPRING_TORSION_DAMPING]
            else:
                kk = p[SPRING_STIFFNESS + k]
                dk = p[SPRING_DAMPING]
            Pi += 0.5 * kk * diff * diff
            f = kk * diff + dk * (dY[i, k] - dY[j, k])
            F[i, k] += f
            F[j, k] -= f
    return Pi


@njit(cache=True, _nrt=False)
def node_rotational_terms(A, dA, I, Wr, g):
    """Rotational inertia ``Wr = L^T I L`` (105, 114) and gyroscopic term ``g`` of one node.

    .. math:: g = L^T (I \\dot L \\dot A + \\omega \\times I \\omega), \\quad \\omega = L \\dot A

    ``I`` is the principal inertia (3,) [kg m^2]. Writes into ``Wr`` (3x3) and ``g`` (3,).
    """
    _rotational_terms_from_trig(math.cos(A[1]), math.sin(A[1]), math.cos(A[2]), math.sin(A[2]), dA, I, Wr, g)


@njit(cache=True, inline="always")
def _rotational_terms_from_trig(cth, sth, cph, sph, dA, I, Wr, g):
    """:func:`node_rotational_terms` from the cosines and sines of ``theta`` and ``phi``."""
    # L rows
    L00, L01, L02 = -sth, 0.0, 1.0
    L10, L11, L12 = sph * cth, cph, 0.0
    L20, L21, L22 = cph * cth, -sph, 0.0
    for a in range(3):
        La = (L00, L10, L20) if a == 0 else ((L01, L11, L21) if a == 1 else (L02, L12, L22))
        for b in range(3):
            Lb = (L00, L10, L20) if b == 0 else ((L01, L11, L21) if b == 1 else (L02, L12, L22))
            Wr[a, b] = I[0] * La[0] * Lb[0] + I[1] * La[1] * Lb[1] + I[2] * La[2] * Lb[2]
    dth, dph = dA[1], dA[2]
    w0 = L00 * dA[0] + L02 * dA[2]
    w1 = L10 * dA[0] + L11 * dA[1]
    w2 = L20 * dA[0] + L21 * dA[1]
    # Ldot dA
    ld0 = -cth * dth * dA[0]
    ld1 = (cph * cth * dph - sph * sth * dth) * dA[0] - sph * dph * dA[1]
    ld2 = (-sph * cth * dph - cph * sth * dth) * dA[0] - cph * dph * dA[1]
    Iw0, Iw1, Iw2 = I[0] * w0, I[1] * w1, I[2] * w2
    t0 = I[0] * ld0 + (w1 * Iw2 - w2 * Iw1)
    t1 = I[1] * ld1 + (w2 * Iw0 - w0 * Iw2)
    t2 = I[2] * ld2 + (w0 * Iw1 - w1 * Iw0)
    g[0] = L00 * t0 + L10 * t1 + L20 * t2
    g[1] = L01 * t0 + L11 * t1 + L21 * t2
    g[2] = L02 * t0 + L12 * t1 + L22 * t2


@njit(cache=True)
def node_terms(Y, dY, node_params, gravity, Y_ref, immobile, Wr, w):
    """:func:`node_terms_into` with a scratch array of its own (one allocation per call)."""
    return node_terms_into(Y, dY, node_params, gravity, Y_ref, immobile, Wr, w, np.empty(EDGE_SCRATCH_SHAPE))


@njit(cache=True, _nrt=False)
def node_terms_into(Y, dY, node_params, gravity, Y_ref, immobile, Wr, w, scratch):
    """Per-node inertia and the non-interconnection part of ``w`` (113).

    Fills ``Wr`` (N, 3, 3) with the rotational inertia blocks and sets ``w`` (N, 6) to
    ``(-m g, gyroscopic)``; the immobile model uses ``W(Y_ref)`` and no gyroscopic term.
    Returns a status (Euler singularity of a node is checked where ``L^-1`` is needed, by the
    caller). Allocates nothing: ``scratch`` (``EDGE_SCRATCH_SHAPE``) block 15 is used.
    """
    g3 = scratch[15, 0]
    zero = scratch[15, 1]
    zero[0] = 0.0
    zero[1] = 0.0
    zero[2] = 0.0
    for k in range(Y.shape[0]):
        m = node_params[k, NODE_MASS]
        for a in range(3):
            w[k, a] = -m * gravity[a]
        I = node_params[k, NODE_INERTIA:NODE_INERTIA + 3]
        if immobile:
            node_rotational_terms(Y_ref[k, 3:6], zero, I, Wr[k], g3)
            w[k, 3] = 0.0
            w[k, 4] = 0.0
            w[k, 5] = 0.0
        else:
            node_rotational_terms(Y[k, 3:6], dY[k, 3:6], I, Wr[k], g3)
            w[k, 3] = g3[0]
            w[k, 4] = g3[1]
            w[k, 5] = g3[2]
    return STATUS_OK


@njit(cache=True, _nrt=False)
def solve_node_rotation(A, I, b, out):
    """Solve ``(L^T I L) x = b`` for one node as ``x = L^-1 I^-1 L^-T b``; False if singular."""
    cth = math.cos(A[1])
    if abs(cth) < EULER_SINGULARITY_COS:
        return False
    sth = math.sin(A[1])
    cph, sph = math.cos(A[2]), math.sin(A[2])
    tth = sth / cth
    # Linv rows: [0, sph/cth, cph/cth], [0, cph, -sph], [1, sph*tth, cph*tth]
    # y = Linv^T b
    y0 = b[2] / I[0]
    y1 = (sph / cth * b[0] + cph * b[1] + sph * tth * b[2]) / I[1]
    y2 = (cph / cth * b[0] - sph * b[1] + cph * tth * b[2]) / I[2]
    out[0] = sph / cth * y1 + cph / cth * y2
    out[1] = cph * y1 - sph * y2
    out[2] = y0 + sph * tth * y1 + cph * tth * y2
    return True


@njit(cache=True)
def interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w):
    """:func:`interconnection_terms_into` with scratch and node frames of its own."""
    return interconnection_terms_into(Y, dY, edge_index, edge_params, Y_ref, immobile, w,
                                      np.empty(EDGE_SCRATCH_SHAPE), np.empty((Y.shape[0], NODE_FRAME_BLOCKS, 3, 3)))


@njit(cache=True, _nrt=False)
def interconnection_terms_into(Y, dY, edge_index, edge_params, Y_ref, immobile, w, scratch, frames):
    """Add every interconnection's part of ``w`` (113) into ``w``: ``dPi/dY + dD/d(dY)``, or the
    immobile model's ``K y + D dy``. Returns a status code. Allocates nothing: ``scratch`` is a
    float64 array of shape ``EDGE_SCRATCH_SHAPE`` and ``frames`` one of shape (N, NODE_FRAME_BLOCKS, 3, 3),
    both overwritten (``frames`` with every node's :func:`node_frames_into`)."""
    if immobile:
        linear_edges(Y, dY, Y_ref, edge_index, edge_params, w)
        return STATUS_OK
    node_frames_into(Y, frames)
    _, status = elastic_edges_into(Y, edge_index, edge_params, w, scratch, frames)
    if status != STATUS_OK:
        return status
    damping_edges_into(Y, dY, edge_index, edge_params, w, scratch, frames)
    return STATUS_OK


@njit(cache=True)
def elastic_accelerations(Y, dY, Fc, node_params, edge_index, edge_params, gravity, Y_ref, immobile):
    """``Y''`` of the free elastic system ``W(Y) Y'' + w(Y, Y') = F`` (113) with ``F_0 = 0``.

    ``Fc`` (N, 6) holds the generalized contact forces on every node (row 0 ignored). ``node_params``
    rows may carry charts (``NODE_WIDTH_CHARTED`` columns): ``Y`` are then the angles in each node's
    chart. Returns ``(ddY, status)``.
    """
    N = Y.shape[0]
    Wr = np.empty((N, 3, 3))
    w = np.empty((N, 6))
    node_terms(Y, dY, node_params, gravity, Y_ref, immobile, Wr, w)
    if immobile:
        status = interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w)
    else:  # interconnection_terms_into with each node's frames in its chart (node_params rows)
        scratch = np.empty(EDGE_SCRATCH_SHAPE)
        frames = np.empty((N, NODE_FRAME_BLOCKS, 3, 3))
        node_frames_charted_into(Y, node_params, frames)
        _, status = elastic_edges_into(Y, edge_index, edge_params, w, scratch, frames)
        if status == STATUS_OK:
            damping_edges_into(Y, dY, edge_index, edge_params, w, scratch, frames)
    if status != STATUS_OK:
        return np.zeros((N, 6)), status
    ddY = np.empty((N, 6))
    b = np.empty(3)
    out = np.empty(3)
    for k in range(N):
        m = node_params[k, NODE_MASS]
        for a in range(6):
            f = (Fc[k, a] if k > 0 else 0.0) - w[k, a]
            if a < 3:
                ddY[k, a] = f / m
            else:
                b[a - 3] = f
        A = Y_ref[k, 3:6] if immobile else Y[k, 3:6]
        if not solve_node_rotation(A, node_params[k, NODE_INERTIA:NODE_INERTIA + 3], b, out):
            return ddY, STATUS_EULER_SINGULAR
        ddY[k, 3] = out[0]
        ddY[k, 4] = out[1]
        ddY[k, 5] = out[2]
    return ddY, STATUS_OK
