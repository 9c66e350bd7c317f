"""The fused right-hand side of the spatial cooperative system (docs/model.md s.5, 177, 183).

The numba kernels, kept for the numba code of ``coopctrl/`` that still calls them (its integrators, a record's
node poses); :class:`~plants.cooperative.CooperativePlant` calls the compiled core (``plants/core/cooperative_*``),
which computes the same numbers. This module goes with its last caller.

One numba call evaluates ``x' = f(t, x, tau)`` for ``x = (z, z')``, ``z = (q_1..q_m, Y_0)``:

.. math::
    \\Gamma(z) z'' + \\phi(z, z') = (\\tau, 0), \\quad
    \\Gamma = \\mathrm{blockdiag}(N_1, \\dots, N_m, W_0), \\quad
    N_i = H_i + J_i^T W_i J_i, \\quad
    n_i = h_i + J_i^T (W_i \\dot J_i \\dot q_i + w_i)

``Gamma`` is block diagonal, so each arm's block is factored on its own (Cholesky) and the
object's block ``W_0 = blockdiag(m_0 I, L^T I L)`` is inverted in closed form: the cost is
linear in m. An arm of kind ``ARM_CONTACT_POINT`` is an actuated node without arm dynamics:
its coordinates are the node pose itself (``J = I``, ``H = h = 0``).

The interconnections' forces, dampers included (frame invariant by default, docs/model.md s.3), come from
the kernels of :mod:`plants.elastic`. Rotation charts (docs/model.md s.2): rows of ``node_params`` wider
than ``NODE_CHART_KIND`` carry each node's chart (the object's and contact points' stored, an arm of kind
``ARM_SERIAL_OWN_CHART`` in its own), applied to the node frames after they are evaluated; with the
book's 4-column rows nothing else runs. numba keys a cached function on its own file only: after a change to
a kernel it calls from another file, clear the ``__pycache__`` folders of plants/.

Allocation-free entry points (issue 10): ``rhs_into`` (the right-hand side into ``dx``),
``control_terms_into`` and ``node_state_into``, each with a workspace made once per run by
``make_workspace`` / ``make_control_workspace`` (namedtuples of preallocated arrays, documented
below). ``rhs_kernel`` and ``node_state_kernel`` are thin wrappers that make a workspace per call.

Compilation (issue 10: speed and start-up). The allocation-free kernels here and their callees are
compiled with ``_nrt=False``: without numba's reference counting, which otherwise costs an atomic
increment and decrement per array argument and per view on every call (about a third of the
right-hand side). They call the arm, node and edge kernels (each compiled and cached once) rather
than inlining them: inlining made each entry point compile its own copy of the chain kernel (tens of
seconds on a cold cache) and gained about 5 % per call.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

# Every spatial serial arm (DH or URDF) is evaluated by the general-chain kernel.
from plants.arms._chain_kernels import chain_arm_potential as spatial_arm_potential
from plants.arms._chain_kernels import CHAIN_WORK_WIDTH
from plants.arms._chain_kernels import chain_arm_pose_into, chain_arm_terms_into
from plants.cooperative._linalg import cholesky_solve_n
from plants.elastic._layout import NODE_CHART_KIND, STATUS_EULER_SINGULAR, STATUS_OK, STATUS_SINGULAR_MASS
from plants._numba_frames import body_rate_map_inverse, rotation_zyx_into
from plants.elastic._spatial_kernels import (
    EDGE_SCRATCH_SHAPE,
    FRAME_CHART,
    NODE_FRAME_BLOCKS,
    damping_edges_into,
    elastic_edges_into,
    linear_edges,
    node_frames_charted_into,
    node_frames_into,
    node_frames_terms_into,
    node_terms_into,
    solve_node_rotation,
)

from plants.cooperative.plant_args import ARM_CONTACT_POINT, ARM_SERIAL, ARM_SERIAL_OWN_CHART  # noqa: E402, F401



#: Fields of :class:`SpatialWorkspace`, in order (N = m + 1 nodes, n = ``nmax`` = max(6, largest arm dof)).
SpatialWorkspace = namedtuple("SpatialWorkspace", (
    "Y",      # (N, 6) node poses (r [m], ZYX Euler angles [rad]); row 0 = object
    "dY",     # (N, 6) node rates [m/s, rad/s]
    "H",      # (m, n, n) arm inertias H_i [kg m^2], block [:n_i, :n_i] valid for a serial arm
    "h",      # (m, n) arm bias torques h_i [N m]
    "J",      # (m, 6, n) analytic Jacobians J_i; columns past n_i and contact-point rows stay 0
    "Jdq",    # (m, 6) dJ_i/dt dq_i [m/s^2, rad/s^2]; contact-point rows stay 0
    "Wr",     # (N, 3, 3) rotational inertia blocks L^T I L [kg m^2]
    "w",      # (N, 6) node terms w_i: -m g + gyroscopic + interconnections [N, N m]
    "Nm",     # (n, n) one arm's block N_i = H_i + J_i^T W_i J_i (lower triangle), then its Cholesky factor
    "rhs",    # (n,) one arm's right-hand side tau_i - n_i
    "qdd",    # (n,) one arm's joint accelerations
    "v",      # (6,) W_i dJ_i dq_i + w_i of one arm's node
    "WJ",     # (3, n) Wr_i J_i,rot of one arm
    "b3",     # (3,) right-hand side of a node rotation solve
    "o3",     # (3,) its solution
    "chain",  # (n + 1, CHAIN_WORK_WIDTH) work rows of plants.arms._chain_kernels.chain_arm_terms_into
    "edge",   # EDGE_SCRATCH_SHAPE scratch of the plants.elastic._spatial_kernels *_into kernels
    "frames", # (N, NODE_FRAME_BLOCKS, 3, 3) every node's R, dR/dA, L (plants.elastic node_frames_into) and chart
))


@njit(cache=True)
def make_workspace(arm_dof, node_count):
    """A new :class:`SpatialWorkspace` for arms of ``arm_dof`` (m,) dofs and ``node_count`` = m + 1 nodes.

    Every array is zero-filled; :func:`rhs_into` and :func:`node_state_into` overwrite what they
    read (except the zero padding of ``J`` and ``Jdq``, which they never write).
    """
    m = arm_dof.shape[0]
    N = node_count
    nmax = 6
    for i in range(m):
        if arm_dof[i] > nmax:
            nmax = arm_dof[i]
    return SpatialWorkspace(
        np.zeros((N, 6)), np.zeros((N, 6)), np.zeros((m, nmax, nmax)), np.zeros((m, nmax)),
        np.zeros((m, 6, nmax)), np.zeros((m, 6)), np.zeros((N, 3, 3)), np.zeros((N, 6)),
        np.zeros((nmax, nmax)), np.zeros(nmax), np.zeros(nmax), np.zeros(6), np.zeros((3, nmax)),
        np.zeros(3), np.zeros(3),
        np.zeros((nmax + 1, CHAIN_WORK_WIDTH)), np.zeros(EDGE_SCRATCH_SHAPE), np.zeros((N, NODE_FRAME_BLOCKS, 3, 3)),
    )


@njit(cache=True, inline="always")
def _arm_pass(z, dz, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all, wk, frames, status):
    """Kinematics and arm dynamics of every arm, written straight into the stacked arrays
    ``H_all[i, :n, :n]``, ``h_all[i, :n]``, ``J_all[i, :, :n]``, ``Jdq_all[i]`` and the node poses
    ``Y[1:]`` and rates ``dY[1:]``; ``wk`` is the chain kernel's work array; an arm of kind
    ``ARM_SERIAL_OWN_CHART`` writes its node's chart into ``frames[i + 1, FRAME_CHART]``. Allocates nothing.
    (The arm kernel gets whole rows ``H_all[i]`` etc. -- contiguous, so numba compiles it for
    C-layout arrays -- and takes ``n`` from ``q``.)"""
    m = arm_kind.shape[0]
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        if arm_kind[i] != ARM_CONTACT_POINT:
            st = chain_arm_terms_into(z[o:o + n], dz[o:o + n], dh_all[dh_off[i]:dh_off[i] + n],
                                      bases[i], tools[i], gravity, H_all[i], h_all[i], Y[i + 1],
                                      J_all[i], Jdq_all[i], wk, arm_kind[i] == ARM_SERIAL_OWN_CHART,
                                      frames[i + 1, FRAME_CHART])
            if st != 0:
                status[0] = STATUS_EULER_SINGULAR
                status[1] = i + 1
                return
            for a in range(6):
                s = 0.0
                for k in range(n):
                    s += J_all[i, a, k] * dz[o + k]
                dY[i + 1, a] = s
        else:
            for a in range(6):
                Y[i + 1, a] = z[o + a]
                dY[i + 1, a] = dz[o + a]


@njit(cache=True, _nrt=False)
def _accelerations_into(x, tau, arm_kind, arm_dof, q_off, node_params, Y_ref, immobile, status, ws, dx):
    """The accelerations ``dx[nz:]`` from the terms in ``ws`` (``Y``, ``H``, ``h``, ``J``, ``Jdq``, ``Wr``
    and ``w``, the node forces with every interconnection): each arm's ``(H + J^T W J) ddq = tau - h -
    J^T (W Jdq + w)`` by Cholesky, each contact point's and the object's Newton-Euler equations."""
    nz = x.shape[0] // 2
    m = arm_kind.shape[0]
    Y = ws.Y
    H_all = ws.H
    h_all = ws.h
    J_all = ws.J
    Jdq_all = ws.Jdq
    Wr = ws.Wr
    w = ws.w
    b3 = ws.b3
    o3 = ws.o3
    for i in range(m):
        n = arm_dof[i]
        o = q_off[i]
        k = i + 1
        mk = node_params[k, 0]
        if arm_kind[i] != ARM_CONTACT_POINT:
            Nm = ws.Nm
            rhs = ws.rhs
            Ji = J_all[i]
            Hi = H_all[i]
            Wk = Wr[k]
            # WJdq + w at the node
            v = ws.v
            for a in range(3):
                v[a] = mk * Jdq_all[i, a] + w[k, a]
            for a in range(3):
                s = w[k, 3 + a]
                for c in range(3):
                    s += Wk[a, c] * Jdq_all[i, 3 + c]
                v[3 + a] = s
            # WJ = Wr J_rot (3 x n), once per arm
            WJ = ws.WJ
            for a in range(3):
                for c in range(n):
                    t = 0.0
                    for e in range(3):
                        t += Wk[a, e] * Ji[3 + e, c]
                    WJ[a, c] = t
            for r in range(n):
                j0, j1, j2 = Ji[0, r], Ji[1, r], Ji[2, r]
                j3, j4, j5 = Ji[3, r], Ji[4, r], Ji[5, r]
                s = 0.0
                s += j0 * v[0]
                s += j1 * v[1]
                s += j2 * v[2]
                s += j3 * v[3]
                s += j4 * v[4]
                s += j5 * v[5]
                rhs[r] = tau[o + r] - h_all[i, r] - s
                # lower triangle only: cholesky_solve_n reads no entry above the diagonal
                for c in range(r, n):
                    s = Hi[r, c]
                    s += mk * j0 * Ji[0, c]
                    s += mk * j1 * Ji[1, c]
                    s += mk * j2 * Ji[2, c]
                    s += j3 * WJ[0, c]
                    s += j4 * WJ[1, c]
                    s += j5 * WJ[2, c]
                    Nm[c, r] = s
            qdd = ws.qdd
            if not cholesky_solve_n(Nm, rhs, qdd, n):
                status[0] = STATUS_SINGULAR_MASS
                status[1] = k
                return
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
                return
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
        return
    for a in range(3):
        dx[2 * nz - 3 + a] = o3[a]


@njit(cache=True, _nrt=False)
def rhs_into(x, tau, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
             node_params, edge_index, edge_params, Y_ref, immobile, status, ws, dx):
    """Write ``dx = f(x, tau)`` into ``dx``; allocates nothing (all work arrays are in ``ws``).

    Args:
        x: State ``(z, z')``, float64 (2 nz,), C-contiguous.
        tau: Inputs (nz - 6,): joint torques [N m] (or node forces of a contact point).
        arm_kind ... immobile: The plant's packed arrays, in the order of
            :class:`~plants.cooperative.plant_args.PlantArgs`' fields.
        status: int64 (2,): receives a status code (``plants.elastic._layout.STATUS_*``) and
            the node index it concerns; ``STATUS_OK`` = 0.
        ws: A :class:`SpatialWorkspace` from :func:`make_workspace` (``CooperativePlant.workspace()``),
            one per run (not shared between threads). Its content between calls means nothing,
            except that after a successful call ``ws.Y``, ``ws.dY``, ``ws.H``, ``ws.h``, ``ws.J``,
            ``ws.Jdq``, ``ws.Wr`` and ``ws.w`` hold the terms of this state.
        dx: Out: float64 (2 nz,). Left partly written when ``status[0] != STATUS_OK``.
    """
    nz = x.shape[0] // 2
    z = x[:nz]
    dz = x[nz:]
    m = arm_kind.shape[0]
    Y = ws.Y
    dY = ws.dY
    H_all = ws.H
    h_all = ws.h
    J_all = ws.J
    Jdq_all = ws.Jdq
    status[0] = STATUS_OK
    for a in range(6):
        Y[0, a] = z[nz - 6 + a]
        dY[0, a] = dz[nz - 6 + a]
    _arm_pass(z, dz, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
              Y, dY, H_all, h_all, J_all, Jdq_all, ws.chain, ws.frames, status)
    for a in range(nz):
        dx[a] = dz[a]
    if status[0] != STATUS_OK:
        return
    # node terms: W (rotational blocks) and w = gyro - gravity + elastic + damping
    Wr = ws.Wr
    w = ws.w
    if immobile:
        node_terms_into(Y, dY, node_params, gravity, Y_ref, immobile, Wr, w, ws.edge)
        linear_edges(Y, dY, Y_ref, edge_index, edge_params, w)
    else:
        # = node_terms_into + interconnection_terms_into, each node's sines and cosines evaluated once
        node_frames_terms_into(Y, dY, node_params, gravity, ws.frames, Wr, w)
        _, st = elastic_edges_into(Y, edge_index, edge_params, w, ws.edge, ws.frames)
        if st != STATUS_OK:
            status[0] = st
            return
        damping_edges_into(Y, dY, edge_index, edge_params, w, ws.edge, ws.frames)
    _accelerations_into(x, tau, arm_kind, arm_dof, q_off, node_params, Y_ref, immobile, status, ws, dx)


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
def rhs_kernel(x, tau, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
               node_params, edge_index, edge_params, Y_ref, immobile, status):
    """``dx = f(x, tau)`` as a new array: :func:`rhs_into` with a workspace of its own (allocated per
    call); ``status[0]`` receives a status code and ``status[1]`` the node index."""
    ws = make_workspace(arm_dof, arm_kind.shape[0] + 1)
    dx = np.empty_like(x)
    rhs_into(x, tau, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
             node_params, edge_index, edge_params, Y_ref, immobile, status, ws, dx)
    return dx


@njit(cache=True, _nrt=False)
def node_state_into(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity, status, ws):
    """Node poses ``ws.Y`` (N, 6) and rates ``ws.dY`` (N, 6) of a state, plus the arm terms ``ws.H``,
    ``ws.h``, ``ws.J``, ``ws.Jdq`` (see :class:`SpatialWorkspace`); allocates nothing."""
    nz = x.shape[0] // 2
    Y = ws.Y
    dY = ws.dY
    status[0] = STATUS_OK
    for a in range(6):
        Y[0, a] = x[nz - 6 + a]
        dY[0, a] = x[2 * nz - 6 + a]
    _arm_pass(x[:nz], x[nz:], arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
              Y, dY, ws.H, ws.h, ws.J, ws.Jdq, ws.chain, ws.frames, status)


@njit(cache=True, _nrt=False)
def node_poses_into(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, status, ws):
    """The node poses ``ws.Y`` (N, 6) of :func:`node_state_into` alone, bit for bit, by forward kinematics
    (:func:`~plants.arms._chain_kernels.chain_arm_pose_into`: no rates, dynamics or Jacobians; a recorded
    run's ``Y_nodes``). ``status`` as there; allocates nothing."""
    nz = x.shape[0] // 2
    Y = ws.Y
    status[0] = STATUS_OK
    for a in range(6):
        Y[0, a] = x[nz - 6 + a]
    for i in range(arm_kind.shape[0]):
        n = arm_dof[i]
        o = q_off[i]
        if arm_kind[i] != ARM_CONTACT_POINT:
            if chain_arm_pose_into(x[o:o + n], dh_all[dh_off[i]:dh_off[i] + n], bases[i], tools[i],
                                   arm_kind[i] == ARM_SERIAL_OWN_CHART, ws.chain, Y[i + 1]) != 0:
                status[0] = STATUS_EULER_SINGULAR
                status[1] = i + 1
                return
        else:
            for a in range(6):
                Y[i + 1, a] = x[o + a]


@njit(cache=True)
def node_state_kernel(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity, status):
    """Node poses ``Y`` (N, 6) and rates ``dY`` (N, 6) of a state, plus arm terms (for sensors):
    ``(Y, dY, H, h, J, Jdq)``, new arrays (rows of contact points hold zeros)."""
    ws = make_workspace(arm_dof, arm_kind.shape[0] + 1)
    node_state_into(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity, status, ws)
    return ws.Y, ws.dY, ws.H, ws.h, ws.J, ws.Jdq


@njit(cache=True)
def node_frames_state_kernel(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity, node_params, status):
    """``(Y, dY, J, Jdq, frames)`` of a state, new arrays: :func:`node_state_into`, then every node's frames in
    its chart (``frames[k, 0]`` the world rotation ``C_k R(A_k)``, block ``FRAME_CHART`` the chart of a
    charted node; :func:`plants.elastic._spatial_kernels.node_frames_charted_into`)."""
    ws = make_workspace(arm_dof, arm_kind.shape[0] + 1)
    node_state_into(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity, status, ws)
    node_frames_charted_into(ws.Y, node_params, ws.frames)
    return ws.Y, ws.dY, ws.J, ws.Jdq, ws.frames


@njit(cache=True)
def arm_potential_kernel(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, gravity):
    """Gravitational potential energy [J] of all arm links."""
    U = 0.0
    for i in range(arm_kind.shape[0]):
        if arm_kind[i] != ARM_CONTACT_POINT:
            n = arm_dof[i]
            U += spatial_arm_potential(x[q_off[i]:q_off[i] + n], dh_all[dh_off[i]:dh_off[i] + n], bases[i], gravity)
    return U


@njit(cache=True)
def interconnection_kernel(Y, dY, m, edge_index, edge_params, Y_ref, immobile):
    """Generalized spring+damper forces on every node and the wrench each contact applies to the object.

    Returns ``(S, Fw, ok)``: ``S`` (N, 6) with ``S_i = dPi/dY_i + dD/d(dY_i)`` (so ``-S_i`` is
    the generalized force the interconnections apply to node i), and ``Fw`` (m, 6) the wrench
    ``(f, n)`` [N, N m] that the edges between the object and contact i apply to the object,
    force at the contact node and couple, world frame. ``ok`` is False at an Euler singularity
    of the object. New arrays; see :func:`interconnection_into`. The nodes' angles are the book's
    world angles (identity charts); a plant in charts gets these terms from :func:`control_terms_into`.
    """
    N = Y.shape[0]
    S = np.empty((N, 6))
    Fw = np.empty((m, 6))
    ok = interconnection_into(Y, dY, edge_index, edge_params, Y_ref, immobile, S, Fw, np.empty((N, 6)),
                              np.empty(EDGE_SCRATCH_SHAPE), np.empty((N, NODE_FRAME_BLOCKS, 3, 3)))
    return S, Fw, ok


@njit(cache=True, _nrt=False)
def interconnection_into(Y, dY, edge_index, edge_params, Y_ref, immobile, S, Fw, Fe, scratch, frames):
    """:func:`interconnection_kernel` into ``S`` (N, 6) and ``Fw`` (m, 6) (both overwritten); returns ``ok``.

    Allocates nothing: ``Fe`` (N, 6) is work space, ``scratch`` has ``EDGE_SCRATCH_SHAPE``
    (blocks 0-13 for the edge kernels, 14 for ``L_0^-1`` and 15 for ``R_0`` here), ``frames`` (N,
    NODE_FRAME_BLOCKS, 3, 3) receives every node's frames.
    """
    if not immobile:
        node_frames_into(Y, frames)
    return _interconnection_into(Y, dY, edge_index, edge_params, Y_ref, immobile, S, Fw, Fe, scratch, frames, False)


@njit(cache=True, _nrt=False)
def _interconnection_into(Y, dY, edge_index, edge_params, Y_ref, immobile, S, Fw, Fe, scratch, frames, charted):
    """:func:`interconnection_into` with ``frames`` already holding every node's frames (mobile model;
    :func:`plants.elastic._spatial_kernels.node_frames_into` or ``node_frames_terms_into``). ``charted``:
    the nodes' angles are in charts, so the object's world rotation is ``frames[0, 0]`` (``C_0 R(A_0)``)
    rather than ``R(A_0)``."""
    N = Y.shape[0]
    m = Fw.shape[0]
    S[:, :] = 0.0
    Fw[:, :] = 0.0
    Linv = scratch[14]
    R0 = scratch[15]
    ok = body_rate_map_inverse(Y[0, 3:6], Linv)
    if charted:
        for a in range(3):
            for b in range(3):
                R0[a, b] = frames[0, 0, a, b]
    else:
        rotation_zyx_into(Y[0, 3:6], R0)
    for e in range(edge_index.shape[0]):
        Fe[:, :] = 0.0
        ei = edge_index[e:e + 1]
        ep = edge_params[e:e + 1]
        if immobile:
            linear_edges(Y, dY, Y_ref, ei, ep, Fe)
        else:
            elastic_edges_into(Y, ei, ep, Fe, scratch, frames)
            damping_edges_into(Y, dY, ei, ep, Fe, scratch, frames)
        for k in range(N):
            for a in range(6):
                S[k, a] += Fe[k, a]
        i = edge_index[e, 0]
        j = edge_index[e, 1]
        if (i == 0 or j == 0) and ok:
            c = j if i == 0 else i
            f0, f1, f2 = -Fe[0, 0], -Fe[0, 1], -Fe[0, 2]
            # body torque = Linv^T Q_A ; world torque = R0 tb
            tb0 = -(Linv[0, 0] * Fe[0, 3] + Linv[1, 0] * Fe[0, 4] + Linv[2, 0] * Fe[0, 5])
            tb1 = -(Linv[0, 1] * Fe[0, 3] + Linv[1, 1] * Fe[0, 4] + Linv[2, 1] * Fe[0, 5])
            tb2 = -(Linv[0, 2] * Fe[0, 3] + Linv[1, 2] * Fe[0, 4] + Linv[2, 2] * Fe[0, 5])
            d0 = Y[c, 0] - Y[0, 0]
            d1 = Y[c, 1] - Y[0, 1]
            d2 = Y[c, 2] - Y[0, 2]
            Fw[c - 1, 0] += f0
            Fw[c - 1, 1] += f1
            Fw[c - 1, 2] += f2
            for a in range(3):
                tw = R0[a, 0] * tb0 + R0[a, 1] * tb1 + R0[a, 2] * tb2
                Fw[c - 1, 3 + a] += tw
            Fw[c - 1, 3] -= d1 * f2 - d2 * f1
            Fw[c - 1, 4] -= d2 * f0 - d0 * f2
            Fw[c - 1, 5] -= d0 * f1 - d1 * f0
    return ok


#: The arrays :func:`control_terms_into` fills (N = m + 1 nodes; see :class:`plants.cooperative.ControlTerms`).
SpatialControlWorkspace = namedtuple("SpatialControlWorkspace", (
    "ws",      # a SpatialWorkspace: after the call ws.Y, ws.dY, ws.H, ws.h, ws.J, ws.Jdq (and ws.Wr)
    "W",       # (N, 6, 6) node inertia blocks W_i = blockdiag(m_i I, L^T I L) (off-blocks stay 0)
    "w_free",  # (N, 6) gyroscopic - gravity terms of w (no interconnections)
    "S",       # (N, 6) interconnection terms dPi/dY_i + dD/d(dY_i)
    "Fw",      # (m, 6) wrench each contact's edges apply to the object (f [N], couple [N m])
    "Fe",      # (N, 6) work space of one edge's forces
))


@njit(cache=True)
def make_control_workspace(arm_dof, node_count):
    """A new zero-filled :class:`SpatialControlWorkspace`."""
    m = arm_dof.shape[0]
    N = node_count
    return SpatialControlWorkspace(make_workspace(arm_dof, N), np.zeros((N, 6, 6)), np.zeros((N, 6)),
                                   np.zeros((N, 6)), np.zeros((m, 6)), np.zeros((N, 6)))


@njit(cache=True, _nrt=False)
def control_terms_into(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity,
                       node_params, edge_index, edge_params, Y_ref, immobile, status, cws):
    """Every term of :class:`plants.cooperative.ControlTerms` at state ``x`` into ``cws``; allocates nothing.

    Arguments as :func:`rhs_into` (without ``tau``); ``cws`` is a :class:`SpatialControlWorkspace`
    (``CooperativePlant.control_workspace()``), separate from the right-hand side's workspace so that
    integrating the plant does not overwrite the terms a controller reads. Fills ``cws.ws.Y``,
    ``cws.ws.dY``, ``cws.ws.H``, ``cws.ws.h``, ``cws.ws.J``, ``cws.ws.Jdq``, ``cws.W``, ``cws.w_free``,
    ``cws.S`` and ``cws.Fw``. ``status[0]`` is ``STATUS_EULER_SINGULAR`` with ``status[1]`` the node
    at an Euler singularity of an arm's tip (node i) or of the object (node 0, then ``S`` is valid
    and ``Fw`` is not).
    """
    ws = cws.ws
    node_state_into(x, arm_kind, arm_dof, q_off, dh_all, dh_off, bases, tools, gravity, status, ws)
    if status[0] != STATUS_OK:
        return
    N = ws.Y.shape[0]
    if immobile:
        node_terms_into(ws.Y, ws.dY, node_params, gravity, Y_ref, immobile, ws.Wr, cws.w_free, ws.edge)
    else:  # node_terms_into and every node's frames, each node's sines and cosines evaluated once
        node_frames_terms_into(ws.Y, ws.dY, node_params, gravity, ws.frames, ws.Wr, cws.w_free)
    W = cws.W
    for k in range(N):
        for a in range(3):
            W[k, a, a] = node_params[k, 0]
            for b in range(3):
                W[k, 3 + a, 3 + b] = ws.Wr[k, a, b]
    if not _interconnection_into(ws.Y, ws.dY, edge_index, edge_params, Y_ref, immobile, cws.S, cws.Fw, cws.Fe,
                                 ws.edge, ws.frames, node_params.shape[1] > NODE_CHART_KIND):
        status[0] = STATUS_EULER_SINGULAR
        status[1] = 0


@njit(cache=True, _nrt=False)
def control_terms_packed(x, P, status, cws):
    """:func:`control_terms_into` with the packed arrays as one named tuple ``P`` (see :func:`rhs_into_packed`)."""
    control_terms_into(x, P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases, P.tools, P.gravity,
                       P.node_params, P.edge_index, P.edge_params, P.Y_ref, P.immobile, status, cws)



@njit(cache=True, _nrt=False)
def rhs_from_terms_into(x, tau, P, status, cws, dx):
    """``dx = f(x, tau)`` reusing the terms :func:`control_terms_packed` left in ``cws`` for the same state
    ``x`` (the arms' ``H``, ``h``, ``J``, ``Jdq``, the nodes' frames, ``Wr`` and ``w_free``): only the
    interconnection forces and the accelerations are evaluated. The same operations in the same order
    as :func:`rhs_into`, so the same bits. ``P`` as in :func:`rhs_into_packed`; ``cws`` must hold the
    terms of ``x`` (a closed-loop tick's sensors at the true state, before the plant step)."""
    arm_kind, arm_dof, q_off, node_params = P.arm_kind, P.arm_dof, P.q_off, P.node_params
    edge_index, edge_params, Y_ref, immobile = P.edge_index, P.edge_params, P.Y_ref, P.immobile
    ws = cws.ws
    nz = x.shape[0] // 2
    status[0] = STATUS_OK
    for a in range(nz):
        dx[a] = x[nz + a]
    w = ws.w
    w_free = cws.w_free
    for k in range(w.shape[0]):
        for a in range(6):
            w[k, a] = w_free[k, a]
    if immobile:
        linear_edges(ws.Y, ws.dY, Y_ref, edge_index, edge_params, w)
    else:
        _, st = elastic_edges_into(ws.Y, edge_index, edge_params, w, ws.edge, ws.frames)
        if st != STATUS_OK:
            status[0] = st
            return
        damping_edges_into(ws.Y, ws.dY, edge_index, edge_params, w, ws.edge, ws.frames)
    _accelerations_into(x, tau, arm_kind, arm_dof, q_off, node_params, Y_ref, immobile, status, ws, dx)