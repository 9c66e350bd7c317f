"""The fused right-hand side of the planar cooperative system (MODEL.md s.5, planar reduction).

Same structure as :mod:`plants.cooperative._spatial_kernel` with poses ``(x, z, theta)``,
constant node inertia ``W_i = diag(m_i, m_i, I_i)`` and no gyroscopic terms:

.. math::
    N_i = H_i + J_i^T W_i J_i, \\quad n_i = h_i + J_i^T (W_i \\dot J_i \\dot q_i + w_i), \\quad
    W_0 \\ddot Y_0 = -w_0

The interconnections' forces, dampers included (frame invariant by default, MODEL.md s.3), come from
the kernels of :mod:`plants.elastic`. numba's on-disk cache of this file is keyed on this file alone:
after a change to those kernels, change this file too (or clear ``__pycache__``), or a stale compiled
right-hand side is loaded.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from plants.arms._planar_kernels import planar_arm_potential, planar_arm_terms
from plants.cooperative._linalg import cholesky_solve
from plants.elastic._layout import STATUS_OK, STATUS_SINGULAR_MASS
from plants.elastic._planar_kernels import damping_edges, elastic_edges, interconnection_terms, linear_edges

ARM_SERIAL = 0
ARM_CONTACT_POINT = 1


@njit(cache=True)
def _arm_pass(z, dz, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all):
    m = arm_kind.shape[0]
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        if arm_kind[i] == ARM_SERIAL:
            H = np.empty((n, n))
            h = np.empty(n)
            Yi = np.empty(3)
            J = np.empty((3, n))
            Jdq = np.empty(3)
            planar_arm_terms(z[o:o + n], dz[o:o + n], links_all[links_off[i]:links_off[i] + n],
                             bases[i], tools[i], gravity, H, h, Yi, J, Jdq)
            for a in range(3):
                Y[i + 1, a] = Yi[a]
                Jdq_all[i, a] = Jdq[a]
                s = 0.0
                for k in range(n):
                    J_all[i, a, k] = J[a, k]
                    s += J[a, k] * dz[o + k]
                dY[i + 1, a] = s
            for a in range(n):
                h_all[i, a] = h[a]
                for b in range(n):
                    H_all[i, a, b] = H[a, b]
        else:
            for a in range(3):
                Y[i + 1, a] = z[o + a]
                dY[i + 1, a] = dz[o + a]


@njit(cache=True)
def rhs_kernel(x, tau, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
               node_params, edge_index, edge_params, Y_ref, immobile, status):
    """``dx = f(x, tau)``; ``status[0]`` receives a status code and ``status[1]`` the node index."""
    nz = x.shape[0] // 2
    z = x[:nz]
    dz = x[nz:]
    m = arm_kind.shape[0]
    N = m + 1
    nmax = 3
    for i in range(m):
        if arm_dof[i] > nmax:
            nmax = arm_dof[i]
    Y = np.empty((N, 3))
    dY = np.empty((N, 3))
    H_all = np.empty((m, nmax, nmax))
    h_all = np.empty((m, nmax))
    J_all = np.empty((m, 3, nmax))
    Jdq_all = np.empty((m, 3))
    status[0] = STATUS_OK
    for a in range(3):
        Y[0, a] = z[nz - 3 + a]
        dY[0, a] = dz[nz - 3 + a]
    _arm_pass(z, dz, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all)
    dx = np.empty_like(x)
    dx[:nz] = dz
    w = np.zeros((N, 3))
    for k in range(N):
        w[k, 0] = -node_params[k, 0] * gravity[0]
        w[k, 1] = -node_params[k, 0] * gravity[1]
    st = interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w)
    if st != STATUS_OK:
        status[0] = st
        return dx
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        k = i + 1
        mk = node_params[k, 0]
        Ik = node_params[k, 1]
        if arm_kind[i] == ARM_SERIAL:
            Nm = np.empty((n, n))
            rhs = np.empty(n)
            v0 = mk * Jdq_all[i, 0] + w[k, 0]
            v1 = mk * Jdq_all[i, 1] + w[k, 1]
            v2 = Ik * Jdq_all[i, 2] + w[k, 2]
            for r in range(n):
                rhs[r] = tau[o + r] - h_all[i, r] - (J_all[i, 0, r] * v0 + J_all[i, 1, r] * v1 + J_all[i, 2, r] * v2)
                for c in range(r, n):
                    s = (H_all[i, r, c] + mk * (J_all[i, 0, r] * J_all[i, 0, c] + J_all[i, 1, r] * J_all[i, 1, c])
                         + Ik * J_all[i, 2, r] * J_all[i, 2, c])
                    Nm[r, c] = s
                    Nm[c, r] = s
            qdd = np.empty(n)
            if not cholesky_solve(Nm, rhs, qdd):
                status[0] = STATUS_SINGULAR_MASS
                status[1] = k
                return dx
            for r in range(n):
                dx[nz + o + r] = qdd[r]
        else:
            dx[nz + o] = (tau[o] - w[k, 0]) / mk
            dx[nz + o + 1] = (tau[o + 1] - w[k, 1]) / mk
            dx[nz + o + 2] = (tau[o + 2] - w[k, 2]) / Ik
    dx[2 * nz - 3] = -w[0, 0] / node_params[0, 0]
    dx[2 * nz - 2] = -w[0, 1] / node_params[0, 0]
    dx[2 * nz - 1] = -w[0, 2] / node_params[0, 1]
    return dx


@njit(cache=True)
def node_state_kernel(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status):
    """Node poses ``Y`` (N, 3) and rates ``dY`` (N, 3), plus the arm terms."""
    nz = x.shape[0] // 2
    m = arm_kind.shape[0]
    nmax = 3
    for i in range(m):
        if arm_dof[i] > nmax:
            nmax = arm_dof[i]
    Y = np.empty((m + 1, 3))
    dY = np.empty((m + 1, 3))
    H_all = np.empty((m, nmax, nmax))
    h_all = np.empty((m, nmax))
    J_all = np.zeros((m, 3, nmax))
    Jdq_all = np.zeros((m, 3))
    status[0] = STATUS_OK
    for a in range(3):
        Y[0, a] = x[nz - 3 + a]
        dY[0, a] = x[2 * nz - 3 + a]
    _arm_pass(x[:nz], x[nz:], arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all)
    return Y, dY, H_all, h_all, J_all, Jdq_all


@njit(cache=True)
def arm_potential_kernel(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, gravity):
    """Gravitational potential energy [J] of all arm links."""
    U = 0.0
    for i in range(arm_kind.shape[0]):
        if arm_kind[i] == ARM_SERIAL:
            n = arm_dof[i]
            U += planar_arm_potential(x[q_off[i]:q_off[i] + n], links_all[links_off[i]:links_off[i] + n], bases[i], gravity)
    return U


@njit(cache=True)
def interconnection_kernel(Y, dY, m, edge_index, edge_params, Y_ref, immobile):
    """Planar analogue of the spatial ``interconnection_kernel``: ``(S (N,3), Fw (m,3), True)``."""
    N = Y.shape[0]
    S = np.zeros((N, 3))
    Fw = np.zeros((m, 3))
    Fe = np.zeros((N, 3))
    for e in range(edge_index.shape[0]):
        Fe[:, :] = 0.0
        ei = edge_index[e:e + 1]
        ep = edge_params[e:e + 1]
        if immobile:
            linear_edges(Y, dY, Y_ref, ei, ep, Fe)
        else:
            elastic_edges(Y, ei, ep, Fe)
            damping_edges(Y, dY, ei, ep, Fe)
        for k in range(N):
            for a in range(3):
                S[k, a] += Fe[k, a]
        i = edge_index[e, 0]
        j = edge_index[e, 1]
        if i == 0 or j == 0:
            c = j if i == 0 else i
            f0, f1 = -Fe[0, 0], -Fe[0, 1]
            d0 = Y[c, 0] - Y[0, 0]
            d1 = Y[c, 1] - Y[0, 1]
            Fw[c - 1, 0] += f0
            Fw[c - 1, 1] += f1
            Fw[c - 1, 2] += -Fe[0, 2] - (d0 * f1 - d1 * f0)
    return S, Fw, True
