"""The plant's energy inside the compiled tick, from the control terms the tick already has.

:func:`plant_energy` is the kernel form of ``CooperativePlant.energy`` / ``kinetic_energy``
(docs/model.md s.3), allocation free:

.. math::
    T = \\tfrac12 \\sum_i \\dot q_i^T H_i \\dot q_i + \\tfrac12 \\sum_{k=0}^{m} \\dot Y_k^T W_k \\dot Y_k,
    \\qquad E = T + \\Pi(Y) - \\sum_k m_k\\, g \\cdot r_k + U_{arms}(q)

(``dq_i^T N_i dq_i = dq_i^T H_i dq_i + dY_i^T W_i dY_i`` with ``dY_i = J_i dq_i``: the same
kinetic energy as ``1/2 z'^T Gamma z'``; a contact point has ``H = 0``). A serial arm is of kind
``ARM_SERIAL`` or, its node in its own rotation chart, ``ARM_SERIAL_OWN_CHART``: every term is the
same in any chart (``dY^T W dY`` is the node's kinetic energy). It reads ``Y``, ``dY``,
``H`` and ``W`` of a control workspace filled at ``x`` (``control_terms_into``) and uses that
workspace's edge scratch, node frames and chain work rows as scratch; ``F`` (N, p) is scratch
for the elastic gradient and ``dY0`` (N, p) zeros (the immobile model's potential).
"""

from __future__ import annotations

from numba import njit
from numba.extending import overload

from plants.arms._chain_kernels import chain_arm_potential_into
from plants.arms._planar_kernels import planar_arm_potential
from plants.elastic import _planar_kernels as _pe
from plants.elastic import _spatial_kernels as _se
from plants.cooperative._spatial_kernel import ARM_CONTACT_POINT
from plants.cooperative.plant_args import is_spatial


@njit(cache=True)
def _kinetic(x, arm_kind, arm_dof, q_off, Y, dY, H, W):
    nz = x.shape[0] // 2
    p = dY.shape[1]
    T = 0.0
    for i in range(arm_kind.shape[0]):
        if arm_kind[i] == ARM_CONTACT_POINT:
            continue
        o = nz + q_off[i]
        for r in range(arm_dof[i]):
            s = 0.0
            for c in range(arm_dof[i]):
                s += H[i, r, c] * x[o + c]
            T += x[o + r] * s
    for k in range(Y.shape[0]):
        for a in range(p):
            s = 0.0
            for b in range(p):
                s += W[k, a, b] * dY[k, b]
            T += dY[k, a] * s
    return 0.5 * T


@njit(cache=True)
def _gravity_potential(Y, node_params, gravity):
    U = 0.0
    for k in range(Y.shape[0]):
        s = 0.0
        for a in range(gravity.shape[0]):
            s += Y[k, a] * gravity[a]
        U -= node_params[k, 0] * s
    return U


@njit(cache=True)
def _spatial_energy(x, P, cws, F, dY0):
    arm_kind, arm_dof, q_off, tables, table_off, bases = P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases
    gravity, node_params, edge_index, edge_params = P.gravity, P.node_params, P.edge_index, P.edge_params
    Y_ref, immobile = P.Y_ref, P.immobile
    ws = cws.ws
    T = _kinetic(x, arm_kind, arm_dof, q_off, ws.Y, ws.dY, ws.H, cws.W)
    F[:, :] = 0.0
    status = 0
    if immobile:
        Pi = _se.linear_edges(ws.Y, dY0, Y_ref, edge_index, edge_params, F)
    else:
        Pi, status = _se.elastic_edges_into(ws.Y, edge_index, edge_params, F, ws.edge, ws.frames)
    U = 0.0
    for i in range(arm_kind.shape[0]):
        if arm_kind[i] != ARM_CONTACT_POINT:  # a serial arm, its node in the world or in its own chart
            n = arm_dof[i]
            U += chain_arm_potential_into(x[q_off[i]:q_off[i] + n], tables[table_off[i]:table_off[i] + n], bases[i], gravity,
                                  ws.chain)
    return T + Pi + _gravity_potential(ws.Y, node_params, gravity) + U, T, status


@njit(cache=True)
def _planar_energy(x, P, cws, F, dY0):
    arm_kind, arm_dof, q_off, tables, table_off, bases = P.arm_kind, P.arm_dof, P.q_off, P.tables, P.table_off, P.bases
    gravity, node_params, edge_index, edge_params = P.gravity, P.node_params, P.edge_index, P.edge_params
    Y_ref, immobile = P.Y_ref, P.immobile
    ws = cws.ws
    T = _kinetic(x, arm_kind, arm_dof, q_off, ws.Y, ws.dY, ws.H, cws.W)
    F[:, :] = 0.0
    status = 0
    if immobile:
        Pi = _pe.linear_edges(ws.Y, dY0, Y_ref, edge_index, edge_params, F)
    else:
        Pi, status = _pe.elastic_edges(ws.Y, edge_index, edge_params, F)
    U = 0.0
    for i in range(arm_kind.shape[0]):
        if arm_kind[i] == 0:
            n = arm_dof[i]
            U += planar_arm_potential(x[q_off[i]:q_off[i] + n], tables[table_off[i]:table_off[i] + n], bases[i], gravity)
    return T + Pi + _gravity_potential(ws.Y, node_params, gravity) + U, T, status


def plant_energy(x, P, cws, F, dY0):
    """``(E, T, status)``: total and kinetic energy [J] at ``x`` (``cws`` filled at ``x``); ``status``
    nonzero where the elastic potential is undefined (coincident nodes). Compiled per kind (the type of
    ``P``'s bases, as ``coopctrl.loop.kernel._terms``)."""
    raise NotImplementedError("called from numba only")


@overload(plant_energy)
def _plant_energy_typed(x, P, cws, F, dY0):
    energy = _spatial_energy if is_spatial(P) else _planar_energy

    def impl(x, P, cws, F, dY0):
        return energy(x, P, cws, F, dY0)
    return impl
