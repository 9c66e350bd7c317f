"""The load-distribution QP's contact inputs from the plant's control terms, in numba: the one definition of each.

The compiled tick (:func:`coopctrl.loop.kernel._qp_rows`, on the measured terms of every tick) and the
wrappers of :mod:`coopctrl.loop.qp_inputs` (the loaded start and the pre-flight, on a
:class:`~plants.cooperative.control_terms.ControlTerms`) call these functions; the rows they feed are
those of :mod:`.assembly`. Node ``k = i + 1`` is contact i's node; ``Y`` (m+1, p) the node poses [m, rad],
``p = 6`` spatial (``Y_k = (r_k, A_k)``, ``A_k = (psi, theta, phi)`` the ZYX Euler angles), ``p = 3``
planar (``Y_k = (x_k, z_k, th_k)``).

- :func:`contact_normals_into`: the inward unit normal of each contact, its node frame's approach
  (x) axis, for the ``min_grip`` and ``friction`` families:

  .. math::
      n_i = \\frac{R(A_k) e_x}{|R(A_k) e_x|} \\text{ (spatial)}, \\qquad
      n_i = \\frac{(\\cos th_k, \\sin th_k)}{|(\\cos th_k, \\sin th_k)|} \\text{ (planar)};

- :func:`torque_model_into`: the ``torque_limits`` family's model of arm i's joint torques [N m] as a
  function of its contact wrench ``F_i`` [N, N m] (world force and world moment),

  .. math::
      \\tau_i = Jg_i^T F_i + \\mathrm{bias}_i, \\qquad
      \\mathrm{bias}_i = H_i \\ddot q_i + h_i + J_i^T (W_k \\ddot Y^N_k + w_{free,k}),

  at the nominal node accelerations ``ddYn`` [m/s^2, rad/s^2]; ``ddq_i`` [rad/s^2] tracks them,
  ``J_i ddq_i = ddYn_k - Jdq_i``: ``ddq_i = J_i^-1 (ddYn_k - Jdq_i)`` for a square arm (LU solve),
  ``ddq_i = J^# (ddYn_k - Jdq_i)`` with ``J^# = N^-1 J^T (J N^-1 J^T)^-1``, ``N = H_i + J_i^T W_k J_i``
  for a redundant arm (:func:`~coopctrl.controllers._kernels.consistent_acceleration_into`, the
  redundant computed torque's resolution), and ``ddq_i = 0`` where that solve is singular (a pivot
  ``<= 1e-13`` of the matrix's largest entry). ``Jg_i`` (p, n_i) maps the joint rates to the node's world
  twist: ``J_i`` with, spatial, its angular rows ``Jg_i[3:] = R(A_k) L(A_k) J_i[3:]`` (``L`` the body-rate
  map, ``omega_body = L(A) dA/dt``). A contact point (``arm_kind[i] != 0``, ``n_i = p``) carries the
  wrench directly: ``Jg_i = I``, ``bias_i = W_k ddYn_k + w_free_k``.

Callers pass C-contiguous float64 arrays, int64 integer arrays and a bool ``spatial``, the compiled tick's
argument types, so that one compiled (and cached) specialisation serves both
(``tests/test_load_distribution_contact_model.py``). Neither function allocates.
"""

from __future__ import annotations

import math

from numba import njit

from coopctrl.controllers._kernels import consistent_acceleration_into, lu_solve_into
from plants.cooperative.loaded_state import body_rate_map_into
from plants.frames import rotation_zyx_into


@njit(cache=True)
def contact_normals_into(Y, spatial, nrm, R):
    """Write the inward unit normals ``n_i`` (module docstring) of the ``m = nrm.shape[0]`` contacts into
    ``nrm`` (m, 3) spatial or (m, 2) planar, from the node poses ``Y`` (m+1, p) [m, rad]; ``R`` (3, 3)
    is scratch."""
    m = nrm.shape[0]
    npos = 3 if spatial else 2
    for i in range(m):
        if spatial:
            rotation_zyx_into(Y[i + 1, 3:6], R)
            for a in range(3):
                nrm[i, a] = R[a, 0]
        else:
            nrm[i, 0] = math.cos(Y[i + 1, 2])
            nrm[i, 1] = math.sin(Y[i + 1, 2])
        s = 0.0
        for a in range(npos):
            s += nrm[i, a] * nrm[i, a]
        length = math.sqrt(s)
        for a in range(npos):
            nrm[i, a] = nrm[i, a] / length


@njit(cache=True)
def torque_model_into(spatial, Y, ddYn, W, w_free, H, h, J, Jdq, arm_kind, arm_dof, Jg, bias, Wa, rhs_t, qdd, piv,
                      wv, wm, R3):
    """Write the torque model ``tau_i = Jg_i^T F_i + bias_i`` (module docstring) of every arm.

    Inputs, the plant's control terms (:class:`~plants.cooperative.control_terms.ControlTerms`, ``nmax``
    joints per arm at most): ``Y`` (m+1, p) node poses [m, rad]; ``ddYn`` (m+1, p) nominal node
    accelerations [m/s^2, rad/s^2]; ``W`` (m+1, p, p) node inertias [kg, kg m^2]; ``w_free`` (m+1, p)
    node gyroscopic-minus-gravity terms [N, N m]; ``H`` (m, nmax, nmax) arm inertias [kg m^2]; ``h``
    (m, nmax) arm bias torques [N m]; ``J`` (m, p, nmax) analytic Jacobians; ``Jdq`` (m, p) ``dJ/dt dq``
    [m/s^2, rad/s^2]; ``arm_kind`` (m,) int64 (nonzero: a contact point); ``arm_dof`` (m,) int64 ``n_i``.

    Outputs: ``Jg`` (m, p, >= max(p, nmax)), arm i's ``Jg_i`` in ``Jg[i, :, :n_i]``; ``bias`` (sum n_i,)
    [N m], the arms' biases stacked in arm order. Scratch: ``Wa``, ``rhs_t`` (p,); ``qdd`` (>= nmax,);
    ``piv`` (>= nmax,) int64; ``wv``, ``wm`` of :func:`~coopctrl.controllers._kernels.control_work`
    (``nmax >= p``); ``R3`` (>= 3, 3, 3).
    """
    m = arm_kind.shape[0]
    p = 6 if spatial else 3
    j0 = 0
    for i in range(m):
        ni = arm_dof[i]
        kk = i + 1
        # W_k ddYn_k + w_free_k
        for a in range(p):
            s = w_free[kk, a]
            for b in range(p):
                s += W[kk, a, b] * ddYn[kk, b]
            Wa[a] = s
        if arm_kind[i] != 0:  # contact point: tau = F + W a + w
            for a in range(p):
                for b in range(p):
                    Jg[i, a, b] = 1.0 if a == b else 0.0
                bias[j0 + a] = Wa[a]
            j0 += ni
            continue
        Ji = J[i]  # (p, nmax): columns :ni are the arm's
        for a in range(p):
            rhs_t[a] = ddYn[kk, a] - Jdq[i, a]
        if ni == p:
            okq = lu_solve_into(Ji, rhs_t, p, wm[0], piv, qdd)
        else:
            okq = consistent_acceleration_into(W[kk], H[i], Ji, rhs_t, ni, wv, wm, piv, qdd)
        if not okq:
            for c in range(ni):
                qdd[c] = 0.0
        for r in range(ni):
            s = h[i, r]
            for c in range(ni):
                s += H[i, r, c] * qdd[c]
            for a in range(p):
                s += Ji[a, r] * Wa[a]
            bias[j0 + r] = s
        if spatial:
            # R(A) L(A): the analytic Jacobian's angular rows to world angular velocity
            RA, LA, RL = R3[0], R3[1], R3[2]
            A = Y[kk, 3:6]
            rotation_zyx_into(A, RA)
            body_rate_map_into(A, LA)
            for a in range(3):
                for b in range(3):
                    RL[a, b] = RA[a, 0] * LA[0, b] + RA[a, 1] * LA[1, b] + RA[a, 2] * LA[2, b]
            for r in range(ni):
                for a in range(3):
                    Jg[i, a, r] = Ji[a, r]
                    s = 0.0
                    for b in range(3):
                        s += RL[a, b] * Ji[3 + b, r]
                    Jg[i, 3 + a, r] = s
        else:
            for r in range(ni):
                for a in range(p):
                    Jg[i, a, r] = Ji[a, r]
        j0 += ni
