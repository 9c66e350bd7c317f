"""The fused right-hand side of the planar cooperative system (docs/model.md s.5, planar reduction).

The numba kernels, kept for the numba code of ``coopctrl/`` that still calls them (its integrators, a record's
node poses); :class:`~plants.cooperative.CooperativePlant` calls the compiled core (``plants/core/cooperative_*``),
which computes the same numbers. This module goes with its last caller.

Same structure as :mod:`plants.cooperative._spatial_kernel` with poses ``(x, z, theta)``,
constant node inertia ``W_i = diag(m_i, m_i, I_i)`` and no gyroscopic terms:

.. math::
    N_i = H_i + J_i^T W_i J_i, \\quad n_i = h_i + J_i^T (W_i \\dot J_i \\dot q_i + w_i), \\quad
    W_0 \\ddot Y_0 = -w_0

The interconnections' forces, dampers included (frame invariant by default, docs/model.md s.3), come from
the kernels of :mod:`plants.elastic`. numba keys a cached function on its own file only: after a change to
a kernel it calls from another file, clear the ``__pycache__`` folders of plants/.

Allocation-free entry points (issue 10): ``rhs_into`` (the right-hand side into ``dx``),
``control_terms_into`` and ``node_state_into``, each with a workspace made once per run by
``make_workspace`` / ``make_control_workspace`` (namedtuples of preallocated arrays, documented
below). ``rhs_kernel`` and ``node_state_kernel`` are thin wrappers that make a workspace per call.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from plants.arms._planar_kernels import PLANAR_WORK_WIDTH, planar_arm_potential, planar_arm_terms_into
from plants.cooperative._linalg import cholesky_solve_n
from plants.elastic._layout import STATUS_OK, STATUS_SINGULAR_MASS
from plants.elastic._planar_kernels import damping_edges, elastic_edges, interconnection_terms, linear_edges

from plants.cooperative.plant_args import ARM_CONTACT_POINT, ARM_SERIAL  # noqa: E402, F401



#: Fields of :class:`PlanarWorkspace`, in order (N = m + 1 nodes, n = ``nmax`` = max(3, largest arm dof)).
PlanarWorkspace = namedtuple("PlanarWorkspace", (
    "Y",      # (N, 3) node poses (x, z [m], theta [rad]); row 0 = object
    "dY",     # (N, 3) node rates
    "H",      # (m, n, n) arm inertias [kg m^2], block [:n_i, :n_i] valid for a serial arm
    "h",      # (m, n) arm bias torques [N m]
    "J",      # (m, 3, n) Jacobians; columns past n_i and contact-point rows stay 0
    "Jdq",    # (m, 3) dJ/dt dq; contact-point rows stay 0
    "w",      # (N, 3) node terms w_i: -m g + interconnections [N, N m]
    "Nm",     # (n, n) one arm's block N_i, then its Cholesky factor
    "rhs",    # (n,) one arm's right-hand side
    "qdd",    # (n,) one arm's joint accelerations
    "chain",  # (n + 1, PLANAR_WORK_WIDTH) work rows of plants.arms._planar_kernels.planar_arm_terms_into
))


@njit(cache=True)
def make_workspace(arm_dof, node_count):
    """A new zero-filled :class:`PlanarWorkspace` for arms of ``arm_dof`` (m,) dofs and ``node_count`` nodes."""
    m = arm_dof.shape[0]
    N = node_count
    nmax = 3
    for i in range(m):
        if arm_dof[i] > nmax:
            nmax = arm_dof[i]
    return PlanarWorkspace(
        np.zeros((N, 3)), np.zeros((N, 3)), np.zeros((m, nmax, nmax)), np.zeros((m, nmax)),
        np.zeros((m, 3, nmax)), np.zeros((m, 3)), np.zeros((N, 3)),
        np.zeros((nmax, nmax)), np.zeros(nmax), np.zeros(nmax), np.zeros((nmax + 1, PLANAR_WORK_WIDTH)),
    )


@njit(cache=True, _nrt=False)
def _arm_pass(z, dz, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all, wk):
    """Arm terms written straight into the stacked arrays and node rows ``Y[1:]``, ``dY[1:]``."""
    m = arm_kind.shape[0]
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        if arm_kind[i] == ARM_SERIAL:
            planar_arm_terms_into(z[o:o + n], dz[o:o + n], links_all[links_off[i]:links_off[i] + n],
                                  bases[i], tools[i], gravity, H_all[i], h_all[i], Y[i + 1],
                                  J_all[i], Jdq_all[i], wk)
            for a in range(3):
                s = 0.0
                for k in range(n):
                    s += J_all[i, a, k] * dz[o + k]
                dY[i + 1, a] = s
        else:
            for a in range(3):
                Y[i + 1, a] = z[o + a]
                dY[i + 1, a] = dz[o + a]


@njit(cache=True, _nrt=False)
def rhs_into(x, tau, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
             node_params, edge_index, edge_params, Y_ref, immobile, status, ws, dx):
    """Write ``dx = f(x, tau)`` into ``dx``; allocates nothing. Same arguments as the spatial
    :func:`plants.cooperative._spatial_kernel.rhs_into`, with ``ws`` a :class:`PlanarWorkspace`."""
    nz = x.shape[0] // 2
    z = x[:nz]
    dz = x[nz:]
    m = arm_kind.shape[0]
    N = m + 1
    Y = ws.Y
    dY = ws.dY
    H_all = ws.H
    h_all = ws.h
    J_all = ws.J
    Jdq_all = ws.Jdq
    status[0] = STATUS_OK
    for a in range(3):
        Y[0, a] = z[nz - 3 + a]
        dY[0, a] = dz[nz - 3 + a]
    _arm_pass(z, dz, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all, ws.chain)
    for a in range(nz):
        dx[a] = dz[a]
    w = ws.w
    for k in range(N):
        w[k, 0] = -node_params[k, 0] * gravity[0]
        w[k, 1] = -node_params[k, 0] * gravity[1]
        w[k, 2] = 0.0
    st = interconnection_terms(Y, dY, edge_index, edge_params, Y_ref, immobile, w)
    if st != STATUS_OK:
        status[0] = st
        return
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        k = i + 1
        mk = node_params[k, 0]
        Ik = node_params[k, 1]
        if arm_kind[i] == ARM_SERIAL:
            Nm = ws.Nm
            rhs = ws.rhs
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
            qdd = ws.qdd
            if not cholesky_solve_n(Nm, rhs, qdd, n):
                status[0] = STATUS_SINGULAR_MASS
                status[1] = k
                return
            for r in range(n):
                dx[nz + o + r] = qdd[r]
        else:
            dx[nz + o] = (tau[o] - w[k, 0]) / mk
            dx[nz + o + 1] = (tau[o + 1] - w[k, 1]) / mk
            dx[nz + o + 2] = (tau[o + 2] - w[k, 2]) / Ik
    dx[2 * nz - 3] = -w[0, 0] / node_params[0, 0]
    dx[2 * nz - 2] = -w[0, 1] / node_params[0, 0]
    dx[2 * nz - 1] = -w[0, 2] / node_params[0, 1]


@njit(cache=True, _nrt=False)
def rhs_into_packed(x, tau, P, status, ws, dx):
    """:func:`rhs_into` with the plant's packed arrays as one named tuple ``P``
    (:class:`~plants.cooperative.plant_args.PlantArgs`, ``CooperativePlant.plant_args``).

    For a compiled caller with numba's reference counting (one that allocates): taking the 13 arrays
    out of its tuple costs it an atomic increment and decrement each, on every call (about 0.3 us);
    passed whole, ``P`` is unpacked here, where nothing is counted."""
    rhs_into(x, tau, P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases, P.tools, P.gravity,
             P.node_params, P.edge_index, P.edge_params, P.Y_ref, P.immobile, status, ws, dx)


@njit(cache=True)
def rhs_kernel(x, tau, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
               node_params, edge_index, edge_params, Y_ref, immobile, status):
    """``dx = f(x, tau)`` as a new array: :func:`rhs_into` with a workspace of its own (allocated per
    call); ``status[0]`` receives a status code and ``status[1]`` the node index."""
    ws = make_workspace(arm_dof, arm_kind.shape[0] + 1)
    dx = np.empty_like(x)
    rhs_into(x, tau, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
             node_params, edge_index, edge_params, Y_ref, immobile, status, ws, dx)
    return dx


@njit(cache=True, _nrt=False)
def node_state_into(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status, ws):
    """Node poses ``ws.Y`` (N, 3), rates ``ws.dY`` and the arm terms into ``ws``; allocates nothing."""
    nz = x.shape[0] // 2
    Y = ws.Y
    dY = ws.dY
    status[0] = STATUS_OK
    for a in range(3):
        Y[0, a] = x[nz - 3 + a]
        dY[0, a] = x[2 * nz - 3 + a]
    _arm_pass(x[:nz], x[nz:], arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
              Y, dY, ws.H, ws.h, ws.J, ws.Jdq, ws.chain)


@njit(cache=True)
def node_state_kernel(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status):
    """Node poses ``Y`` (N, 3) and rates ``dY`` (N, 3), plus the arm terms (new arrays)."""
    ws = make_workspace(arm_dof, arm_kind.shape[0] + 1)
    node_state_into(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status, ws)
    return ws.Y, ws.dY, ws.H, ws.h, ws.J, ws.Jdq


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
    """Planar analogue of the spatial ``interconnection_kernel``: ``(S (N,3), Fw (m,3), True)`` (new arrays)."""
    N = Y.shape[0]
    S = np.empty((N, 3))
    Fw = np.empty((m, 3))
    ok = interconnection_into(Y, dY, edge_index, edge_params, Y_ref, immobile, S, Fw, np.empty((N, 3)))
    return S, Fw, ok


@njit(cache=True, _nrt=False)
def interconnection_into(Y, dY, edge_index, edge_params, Y_ref, immobile, S, Fw, Fe):
    """:func:`interconnection_kernel` into ``S`` (N, 3) and ``Fw`` (m, 3); ``Fe`` (N, 3) is work space.
    Allocates nothing; returns True (the plane has no Euler singularity)."""
    N = Y.shape[0]
    S[:, :] = 0.0
    Fw[:, :] = 0.0
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
    return True


#: The arrays :func:`control_terms_into` fills (planar; see the spatial ``SpatialControlWorkspace``).
PlanarControlWorkspace = namedtuple("PlanarControlWorkspace", (
    "ws",      # a PlanarWorkspace: after the call ws.Y, ws.dY, ws.H, ws.h, ws.J, ws.Jdq
    "W",       # (N, 3, 3) node inertias diag(m_i, m_i, I_i)
    "w_free",  # (N, 3) -m_i g (no interconnections)
    "S",       # (N, 3) interconnection terms
    "Fw",      # (m, 3) wrench each contact's edges apply to the object (f_x, f_z [N], n [N m])
    "Fe",      # (N, 3) work space
))


@njit(cache=True)
def make_control_workspace(arm_dof, node_count):
    """A new zero-filled :class:`PlanarControlWorkspace`."""
    m = arm_dof.shape[0]
    N = node_count
    return PlanarControlWorkspace(make_workspace(arm_dof, N), np.zeros((N, 3, 3)), np.zeros((N, 3)),
                                  np.zeros((N, 3)), np.zeros((m, 3)), np.zeros((N, 3)))


@njit(cache=True, _nrt=False)
def control_terms_into(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity,
                       node_params, edge_index, edge_params, Y_ref, immobile, status, cws):
    """Planar :func:`plants.cooperative._spatial_kernel.control_terms_into`; allocates nothing."""
    ws = cws.ws
    node_state_into(x, arm_kind, arm_dof, q_off, links_all, links_off, bases, tools, gravity, status, ws)
    N = ws.Y.shape[0]
    W = cws.W
    for k in range(N):
        W[k, 0, 0] = node_params[k, 0]
        W[k, 1, 1] = node_params[k, 0]
        W[k, 2, 2] = node_params[k, 1]
        cws.w_free[k, 0] = -node_params[k, 0] * gravity[0]
        cws.w_free[k, 1] = -node_params[k, 0] * gravity[1]
        cws.w_free[k, 2] = 0.0
    interconnection_into(ws.Y, ws.dY, edge_index, edge_params, Y_ref, immobile, cws.S, cws.Fw, cws.Fe)


@njit(cache=True, _nrt=False)
def control_terms_packed(x, P, status, cws):
    """:func:`control_terms_into` with the packed arrays as one named tuple ``P`` (see :func:`rhs_into_packed`)."""
    control_terms_into(x, P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases, P.tools, P.gravity,
                       P.node_params, P.edge_index, P.edge_params, P.Y_ref, P.immobile, status, cws)
