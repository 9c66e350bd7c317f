"""numba kernels of the planar elastic system (docs/model.md s.2-3, planar reduction).

Kept for the numba code that still calls it: the cooperative numba kernels; ElasticSystem calls the compiled core
(plants/core/elastic_*). It goes with its last caller (tests/test_plants_without_numba.py lists it).

``Y`` and ``dY`` are (N, 3) node poses ``(x, z, theta)`` in the vertical x-z plane and their
rates; ``node_params`` is (N, 2) ``(mass, I)``; ``edge_index`` (E, 4) and ``edge_params``
(E, ``EDGE_WIDTH_PLANAR``) follow :mod:`plants.elastic._layout`, whose named columns the kernels read. In the plane ``L = 1``, so ``W`` is constant
``diag(m, m, I)`` and there is no gyroscopic term, and the angle difference is the exact
relative rotation (the torsion spring is rotation invariant for both elements).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from plants.elastic._layout import (DAMPING_BOOK, EDGE_DAMPING_FORM, EDGE_KIND, EDGE_NODE_I, EDGE_NODE_J,
                                    ELEMENT_CENTRAL, ELEMENT_MATRIX, MATRIX_ALPHA_PLANAR, MATRIX_BETA_PLANAR,
                                    MATRIX_C_PLANAR, MATRIX_K, MATRIX_LINEAR_PLANAR, MATRIX_U0_PLANAR, NODE_INERTIA,
                                    NODE_MASS, PLANAR_DAMPING, PLANAR_REST_ANGLE, PLANAR_REST_LENGTH,
                                    PLANAR_REST_OFFSET, PLANAR_STIFFNESS, PLANAR_TORSION, PLANAR_TORSION_DAMPING,
                                    STATUS_COINCIDENT_NODES, STATUS_OK)
from plants.elastic._spatial_kernels import COINCIDENT_FRACTION, linear_matrix_edge, wrap_angle


@njit(cache=True, _nrt=False)
def matrix_edge(Y, dY, i, j, p, F, rates):
    """One matrix element in the plane (co-rotational, docs/model.md s.3 [ours]): the element
    frame turns with node i, ``theta_e = theta_i + alpha``; node j's deformation in it is
    ``u = R_e^T (r_j - r_i) - u0``, ``theta = theta_j - theta_i - beta`` (wrapped), ``Pi = 1/2 d^T
    K_jj d``. Forces: ``dPi/dr_j = R_e g_u = -dPi/dr_i``, ``dPi/dtheta_i = g_u . (p_z, -p_x) -
    g_theta``, ``dPi/dtheta_j = g_theta`` with ``g = K_jj d``, ``p = R_e^T (r_j - r_i)``.
    ``rates=True``: the dampers, ``d_dot = (R_e^T (dr_j - dr_i) + dtheta_i (p_z, -p_x), dtheta_j -
    dtheta_i)``, ``D = 1/2 d_dot^T C_jj d_dot``, forces by the same map with ``g = C_jj d_dot``."""
    te = Y[i, 2] + p[MATRIX_ALPHA_PLANAR]
    c, s = math.cos(te), math.sin(te)
    rx = Y[j, 0] - Y[i, 0]
    rz = Y[j, 1] - Y[i, 1]
    p0 = c * rx + s * rz
    p1 = -s * rx + c * rz
    if rates:
        vx = dY[j, 0] - dY[i, 0]
        vz = dY[j, 1] - dY[i, 1]
        w = dY[i, 2]
        d0 = c * vx + s * vz + w * p1
        d1 = -s * vx + c * vz - w * p0
        d2 = dY[j, 2] - dY[i, 2]
        base = MATRIX_C_PLANAR
    else:
        d0 = p0 - p[MATRIX_U0_PLANAR]
        d1 = p1 - p[MATRIX_U0_PLANAR + 1]
        d2 = wrap_angle(Y[j, 2] - Y[i, 2] - p[MATRIX_BETA_PLANAR])
        base = MATRIX_K
    g0 = p[base + 0] * d0 + p[base + 1] * d1 + p[base + 2] * d2
    g1 = p[base + 3] * d0 + p[base + 4] * d1 + p[base + 5] * d2
    g2 = p[base + 6] * d0 + p[base + 7] * d1 + p[base + 8] * d2
    fx = c * g0 - s * g1
    fz = s * g0 + c * g1
    F[j, 0] += fx
    F[j, 1] += fz
    F[i, 0] -= fx
    F[i, 1] -= fz
    F[i, 2] += g0 * p1 - g1 * p0 - g2
    F[j, 2] += g2
    return 0.5 * (d0 * g0 + d1 * g1 + d2 * g2)


@njit(cache=True, _nrt=False)
def elastic_edges(Y, edge_index, edge_params, F):
    """Add ``dPi/dY`` of every interconnection into ``F``; return ``(Pi, status)``.

    Central element: ``Pi = 1/2 beta (c_x d_x^2 + c_z d_z^2) + 1/2 cA delta^2`` with
    ``d = r_i - r_j``, ``beta = (1 - l/|d|)^2`` and ``delta = theta_i - theta_j - A0``.
    Offset element: ``e = R(theta_i)^T (r_j - r_i) - rho``, ``Pi = 1/2 e^T C e + 1/2 cA delta^2``.
    """
    Pi = 0.0
    for e in range(edge_index.shape[0]):
        i = edge_index[e, EDGE_NODE_I]
        j = edge_index[e, EDGE_NODE_J]
        p = edge_params[e]
        if edge_index[e, EDGE_KIND] == ELEMENT_MATRIX:
            Pi += matrix_edge(Y, Y, i, j, p, F, False)
            continue
        if edge_index[e, EDGE_KIND] == ELEMENT_CENTRAL:
            d0 = Y[i, 0] - Y[j, 0]
            d1 = Y[i, 1] - Y[j, 1]
            Q = p[PLANAR_STIFFNESS] * d0 * d0 + p[PLANAR_STIFFNESS + 1] * d1 * d1
            l = p[PLANAR_REST_LENGTH]
            if l > 0.0:
                s = math.sqrt(d0 * d0 + d1 * d1)
                if s < COINCIDENT_FRACTION * l:
                    return Pi, STATUS_COINCIDENT_NODES
                g = 1.0 - l / s
                a = g * l * Q / (s * s * s)
                g2 = g * g
            else:
                a = 0.0
                g2 = 1.0
            Pi += 0.5 * g2 * Q
            f0 = a * d0 + g2 * p[PLANAR_STIFFNESS] * d0
            f1 = a * d1 + g2 * p[PLANAR_STIFFNESS + 1] * d1
            F[i, 0] += f0
            F[i, 1] += f1
            F[j, 0] -= f0
            F[j, 1] -= f1
        else:
            c, s = math.cos(Y[i, 2]), math.sin(Y[i, 2])
            d0 = Y[j, 0] - Y[i, 0]
            d1 = Y[j, 1] - Y[i, 1]
            e0 = c * d0 + s * d1 - p[PLANAR_REST_OFFSET]
            e1 = -s * d0 + c * d1 - p[PLANAR_REST_OFFSET + 1]
            Pi += 0.5 * (p[PLANAR_STIFFNESS] * e0 * e0 + p[PLANAR_STIFFNESS + 1] * e1 * e1)
            C0 = p[PLANAR_STIFFNESS] * e0
            C1 = p[PLANAR_STIFFNESS + 1] * e1
            f0 = c * C0 - s * C1
            f1 = s * C0 + c * C1
            F[j, 0] += f0
            F[j, 1] += f1
            F[i, 0] -= f0
            F[i, 1] -= f1
            # de/dtheta_i = dR^T d, dR = [[-s, -c], [c, -s]]
            F[i, 2] += C0 * (-s * d0 + c * d1) + C1 * (-c * d0 - s * d1)
        cA = p[PLANAR_TORSION]
        if cA != 0.0:
            dl = wrap_angle(Y[i, 2] - Y[j, 2] - p[PLANAR_REST_ANGLE])
            Pi += 0.5 * cA * dl * dl
            F[i, 2] += cA * dl
            F[j, 2] -= cA * dl
    return Pi, STATUS_OK


@njit(cache=True, _nrt=False)
def damping_edges(Y, dY, edge_index, edge_params, F):
    """Add ``dD/d(dY)`` (110-111) into ``F``; return the Rayleigh function ``D`` [W/2].

    Central element: along the line, ``D = 1/2 d (u^T (dr_i - dr_j))^2``, ``u = (r_i - r_j)/|r_i - r_j|``
    (frame invariant). Offset element, frame-invariant form (docs/model.md s.3 [ours]): the rate of the
    elongation vector in node i's frame,

    .. math::
        \\dot e = R_i^T (\\dot r_j - \\dot r_i) + \\dot\\theta_i (\\rho_z, -\\rho_x), \\quad
        \\rho = R_i^T (r_j - r_i), \\quad D = \\tfrac12 d |\\dot e|^2,

    with generalized force ``(d e_dot / d Y_dot)^T d e_dot``; the book's form (damping form
    ``DAMPING_BOOK``) is ``D = 1/2 d |dr_i - dr_j|^2``. Torsion: ``D = 1/2 dA (dtheta_i -
    dtheta_j)^2`` in both forms (in the plane the Euler-rate difference is the relative angular
    velocity).
    """
    D = 0.0
    for e in range(edge_index.shape[0]):
        i = edge_index[e, EDGE_NODE_I]
        j = edge_index[e, EDGE_NODE_J]
        p = edge_params[e]
        if edge_index[e, EDGE_KIND] == ELEMENT_MATRIX:
            D += matrix_edge(Y, dY, i, j, p, F, True)
            continue
        dd = p[PLANAR_DAMPING]
        if dd != 0.0:
            v0 = dY[i, 0] - dY[j, 0]
            v1 = dY[i, 1] - dY[j, 1]
            d0 = Y[i, 0] - Y[j, 0]
            d1 = Y[i, 1] - Y[j, 1]
            s = math.sqrt(d0 * d0 + d1 * d1)
            if edge_index[e, EDGE_KIND] == ELEMENT_CENTRAL and s > 1e-12:
                vu = (v0 * d0 + v1 * d1) / s
                D += 0.5 * dd * vu * vu
                f0 = dd * vu * d0 / s
                f1 = dd * vu * d1 / s
            elif edge_index[e, EDGE_KIND] == ELEMENT_CENTRAL or edge_index[e, EDGE_DAMPING_FORM] == DAMPING_BOOK:
                D += 0.5 * dd * (v0 * v0 + v1 * v1)
                f0 = dd * v0
                f1 = dd * v1
            else:
                c, sn = math.cos(Y[i, 2]), math.sin(Y[i, 2])
                # rho = R_i^T (r_j - r_i); r_j - r_i = -(d0, d1); dr_j - dr_i = -(v0, v1)
                rho0 = -(c * d0 + sn * d1)
                rho1 = -(-sn * d0 + c * d1)
                w = dY[i, 2]
                ed0 = -(c * v0 + sn * v1) + w * rho1
                ed1 = -(-sn * v0 + c * v1) - w * rho0
                D += 0.5 * dd * (ed0 * ed0 + ed1 * ed1)
                g0 = dd * ed0
                g1 = dd * ed1
                # d e_dot / d dr_j = R_i^T (so d e_dot / d dr_i = -R_i^T); d e_dot / d dtheta_i = (rho_z, -rho_x)
                f0 = -(c * g0 - sn * g1)  # force on node i (node j gets its opposite below)
                f1 = -(sn * g0 + c * g1)
                F[i, 2] += g0 * rho1 - g1 * rho0
            F[i, 0] += f0
            F[i, 1] += f1
            F[j, 0] -= f0
            F[j, 1] -= f1
        dA = p[PLANAR_TORSION_DAMPING]
        if dA != 0.0:
            v = dY[i, 2] - dY[j, 2]
            D += 0.5 * dA * v * v
            F[i, 2] += dA * v
            F[j, 2] -= dA * v
    return D


@njit(cache=True, _nrt=False)
def linear_edges(Y, dY, Y_ref, edge_index, edge_params, F):
    """Immobile unloaded state (4.5): add ``K y + D dy`` per edge into ``F``; return ``Pi``."""
    Pi = 0.0
    for e in range(edge_index.shape[0]):
        i = edge_index[e, EDGE_NODE_I]
        j = edge_index[e, EDGE_NODE_J]
        p = edge_params[e]
        if edge_index[e, EDGE_KIND] == ELEMENT_MATRIX:
            Pi += linear_matrix_edge(Y, dY, Y_ref, i, j, p, F, MATRIX_LINEAR_PLANAR, 3, 2)
            continue
        for k in range(3):
            diff = (Y[i, k] - Y_ref[i, k]) - (Y[j, k] - Y_ref[j, k])
            if k == 2:
                diff = wrap_angle(diff)  # a common rotation is a zero mode, also across +-pi
                dk = p[PLANAR_TORSION_DAMPING]
                kk = p[PLANAR_TORSION]
            else:
                dk = p[PLANAR_DAMPING]
                kk = p[PLANAR_STIFFNESS + k]
            Pi += 0.5 * kk * diff * diff
            f = kk * diff + dk * (dY[i, k] - dY[j, k])
            F[i, k] += f
            F[j, k] -= f
    return Pi


@njit(cache=True, _nrt=False)
def interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w):
    """Add every interconnection's part of ``w`` into ``w`` (planar); returns a status code."""
    if immobile:
        linear_edges(Y, dY, Y_ref, edge_index, edge_params, w)
        return STATUS_OK
    _, status = elastic_edges(Y, edge_index, edge_params, w)
    if status != STATUS_OK:
        return status
    damping_edges(Y, dY, edge_index, edge_params, w)
    return STATUS_OK


@njit(cache=True)
def elastic_accelerations(Y, dY, Fc, node_params, edge_index, edge_params, gravity, Y_ref, immobile):
    """``Y''`` of the free planar elastic system ``W Y'' + w = F`` with ``F_0 = 0``; ``(ddY, status)``."""
    N = Y.shape[0]
    w = np.zeros((N, 3))
    for k in range(N):
        w[k, 0] = -node_params[k, NODE_MASS] * gravity[0]
        w[k, 1] = -node_params[k, NODE_MASS] * gravity[1]
    status = interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w)
    if status != STATUS_OK:
        return np.zeros((N, 3)), status
    ddY = np.empty((N, 3))
    for k in range(N):
        for a in range(3):
            f = (Fc[k, a] if k > 0 else 0.0) - w[k, a]
            ddY[k, a] = f / (node_params[k, NODE_MASS] if a < 2 else node_params[k, NODE_INERTIA])
    return ddY, STATUS_OK
