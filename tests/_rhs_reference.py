"""The cooperative right-hand sides as they were before issue 10 part 6 (one workspace per run),
kept verbatim as the "old" kernels that tests/test_rhs_workspace.py and benchmarks/bench_plant.py
compare the allocation-free kernels with.

They allocate their work arrays on every call (``np.empty``); the physics (arm, node and
interconnection kernels) is the project's, called through the same functions as before. They are
compiled without ``cache=True``: numba's on-disk cache of this file would not notice a change to
the kernels they call (it is keyed on this file alone), and a stale "old" would differ from today's.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from plants.kernels import (
    STATUS_EULER_SINGULAR,
    STATUS_OK,
    STATUS_SINGULAR_MASS,
    cholesky_solve,
    interconnection_terms,
    node_terms,
    planar_arm_terms,
    planar_interconnection_terms,
    solve_node_rotation,
)
from plants.kernels import chain_arm_terms as spatial_arm_terms

ARM_SERIAL = 0
ARM_CONTACT_POINT = 1


@njit  # no on-disk cache: it would keep the kernels it calls as they were when cached
def spatial_arm_pass_old(z, dz, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all, status):
    """Kinematics and arm dynamics of every arm; fills node poses ``Y[1:]`` and rates ``dY[1:]``."""
    m = arm_kind.shape[0]
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        if arm_kind[i] == ARM_SERIAL:
            H = np.empty((n, n))
            h = np.empty(n)
            Yi = np.empty(6)
            J = np.empty((6, n))
            Jdq = np.empty(6)
            st = spatial_arm_terms(z[o:o + n], dz[o:o + n], dh_all[dh_off[i]:dh_off[i] + n],
                                   bases[i], tools[i], gravity, H, h, Yi, J, Jdq)
            if st != 0:
                status[0] = STATUS_EULER_SINGULAR
                status[1] = i + 1
                return
            for a in range(6):
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
            for a in range(6):
                Y[i + 1, a] = z[o + a]
                dY[i + 1, a] = dz[o + a]


@njit  # no on-disk cache: it would keep the kernels it calls as they were when cached
def spatial_rhs_old(x, tau, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
               node_params, edge_index, edge_params, Y_ref, immobile, status):
    """``dx = f(x, tau)``; ``status[0]`` receives a status code and ``status[1]`` the node index."""
    nz = x.shape[0] // 2
    z = x[:nz]
    dz = x[nz:]
    m = arm_kind.shape[0]
    N = m + 1
    nmax = 6
    for i in range(m):
        if arm_dof[i] > nmax:
            nmax = arm_dof[i]
    Y = np.empty((N, 6))
    dY = np.empty((N, 6))
    H_all = np.empty((m, nmax, nmax))
    h_all = np.empty((m, nmax))
    J_all = np.empty((m, 6, nmax))
    Jdq_all = np.empty((m, 6))
    status[0] = STATUS_OK
    for a in range(6):
        Y[0, a] = z[nz - 6 + a]
        dY[0, a] = dz[nz - 6 + a]
    spatial_arm_pass_old(z, dz, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all, status)
    dx = np.empty_like(x)
    dx[:nz] = dz
    if status[0] != STATUS_OK:
        return dx
    # node terms: W (rotational blocks) and w = gyro - gravity + elastic + damping
    Wr = np.empty((N, 3, 3))
    w = np.empty((N, 6))
    node_terms(Y, dY, node_params, gravity, Y_ref, immobile, Wr, w)
    st = interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w)
    if st != STATUS_OK:
        status[0] = st
        return dx
    b3 = np.empty(3)
    o3 = np.empty(3)
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        k = i + 1
        mk = node_params[k, 0]
        if arm_kind[i] == ARM_SERIAL:
            Nm = np.empty((n, n))
            rhs = np.empty(n)
            # WJdq + w at the node
            v = np.empty(6)
            for a in range(3):
                v[a] = mk * Jdq_all[i, a] + w[k, a]
            for a in range(3):
                s = w[k, 3 + a]
                for c in range(3):
                    s += Wr[k, a, c] * Jdq_all[i, 3 + c]
                v[3 + a] = s
            for r in range(n):
                s = 0.0
                for a in range(6):
                    s += J_all[i, a, r] * v[a]
                rhs[r] = tau[o + r] - h_all[i, r] - s
                for c in range(r, n):
                    s = H_all[i, r, c]
                    for a in range(3):
                        s += mk * J_all[i, a, r] * J_all[i, a, c]
                    for a in range(3):
                        t = 0.0
                        for e in range(3):
                            t += Wr[k, a, e] * J_all[i, 3 + e, c]
                        s += J_all[i, 3 + a, r] * t
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
            for a in range(3):
                dx[nz + o + a] = (tau[o + a] - w[k, a]) / mk
                b3[a] = tau[o + 3 + a] - w[k, 3 + a]
            A = Y_ref[k, 3:6] if immobile else Y[k, 3:6]
            if not solve_node_rotation(A, node_params[k, 1:4], b3, o3):
                status[0] = STATUS_EULER_SINGULAR
                status[1] = k
                return dx
            for a in range(3):
                dx[nz + o + 3 + a] = o3[a]
    m0 = node_params[0, 0]
    for a in range(3):
        dx[2 * nz - 6 + a] = -w[0, a] / m0
        b3[a] = -w[0, 3 + a]
    A = Y_ref[0, 3:6] if immobile else Y[0, 3:6]
    if not solve_node_rotation(A, node_params[0, 1:4], b3, o3):
        status[0] = STATUS_EULER_SINGULAR
        status[1] = 0
        return dx
    for a in range(3):
        dx[2 * nz - 3 + a] = o3[a]
    return dx


@njit  # no on-disk cache: it would keep the kernels it calls as they were when cached
def planar_arm_pass_old(z, dz, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
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


@njit  # no on-disk cache: it would keep the kernels it calls as they were when cached
def planar_rhs_old(x, tau, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
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
    planar_arm_pass_old(z, dz, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all)
    dx = np.empty_like(x)
    dx[:nz] = dz
    w = np.zeros((N, 3))
    for k in range(N):
        w[k, 0] = -node_params[k, 0] * gravity[0]
        w[k, 1] = -node_params[k, 0] * gravity[1]
    st = planar_interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w)
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
