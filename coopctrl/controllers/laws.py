"""The control laws of one tick, compiled: the one definition the compiled loop and the Python controllers run.

Each function writes into arrays it is given and allocates nothing, so the compiled tick
(coopctrl/core/control_laws.h, their port) calls it with its work arrays, and :class:`~coopctrl.controllers.LeaderController`,
:class:`~coopctrl.controllers.FollowerForceController`, :class:`~coopctrl.controllers.computed_torque.PostureTask`
and :class:`~coopctrl.controllers.GraspCompliance` call it with arrays they make (docs/model.md s.4-6).
Node poses ``Y`` are ``(position [m], angles [rad])``: ``npos`` = 3 positions then 3 ZYX Euler angles
(spatial, ``p = 6``) or 2 positions then 1 angle (planar, ``p = 3``).

The laws, by the names of the code:

- :func:`pose_error_into`: ``err = target - Y``, angles (``a >= npos``) wrapped into ``[-pi, pi)``
  [m, rad];
- :func:`tracking_acceleration_into`: the computed-torque motion loop's commanded node acceleration
  ``a_cmd = ddY_ref + Kd (dY_ref - dY) + Kp err(target, Y)`` [m/s^2, rad/s^2], ``Kp = omega_n^2``
  [1/s^2], ``Kd = 2 zeta omega_n`` [1/s];
- :func:`leader_target_into`: the leader's node target ``Y_nominal + increment + offset``: its nominal
  node pose (148), the nominal deformation that makes it carry its QP share, and a tuning probe's offset;
- :func:`leader_acceleration_into`: the two above;
- :func:`follower_correction_into`: the followers' force PI in wrench units,
  ``e = F_cmd - F_seen``, ``integral <- clip(integral + e T, -integral_limit, integral_limit)`` [N s, N m s],
  ``corr = F_cmd + kp e + ki integral`` [N, N m] (``corr = F_cmd`` with the force loop open);
- :func:`pose_increment_into`: the node pose increment through the grasp compliance ``C``
  (:meth:`GraspCompliance.pose_increment <coopctrl.controllers.GraspCompliance.pose_increment>`);
  the follower's target is ``pose_increment(corr) + Y_rigid``;
- :func:`follower_acceleration_into`: the two above and :func:`tracking_acceleration_into`;
- :func:`posture_torque_into`: the null-space posture torque of a redundant arm,
  ``tau_0 = m_bar (Kp (q_rest - q) - Kd dq)``, ``m_bar = tr(H) / n`` [kg m^2] (``Kp`` [1/s^2], ``Kd`` [1/s]);
- :func:`arm_torque_into`: the joint torques [N m] that give the node ``a_cmd``
  (:func:`~coopctrl.controllers.computed_torque.node_computed_torque`), the posture torque of a redundant
  arm through the null-space projector included.

The arithmetic, in its operation order, is the compiled tick's: the loop's record is the same whether the
tick inlines it or calls these functions.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from coopctrl.controllers._kernels import (node_torque_into, node_torque_redundant_into, pose_increment_planar_into,
                                           pose_increment_spatial_into)


@njit(cache=True)
def pose_error_into(target, Y, npos, out):
    """``out = target - Y`` with the angle components ``a >= npos`` wrapped into ``[-pi, pi)`` [m, rad]:
    ``e = (e + pi) mod 2 pi - pi``. ``target``, ``Y``, ``out`` (p,)."""
    for a in range(target.shape[0]):
        e = target[a] - Y[a]
        if a >= npos:
            e = (e + np.pi) % (2.0 * np.pi) - np.pi
        out[a] = e


@njit(cache=True)
def tracking_acceleration_into(target, Y, dY_ref, dY, ddY_ref, Kp, Kd, npos, err, a_cmd):
    """The commanded node acceleration of the computed-torque motion loop into ``a_cmd`` (p,):

    .. math:: a_{cmd} = \\ddot Y_{ref} + K_d (\\dot Y_{ref} - \\dot Y) + K_p\\, e, \\qquad
              e = \\mathrm{pose\\_error}(target, Y)

    ``target``, ``Y`` (p,) the node's target and measured pose [m, rad]; ``dY_ref``, ``dY`` (p,) the
    reference and measured rates [m/s, rad/s]; ``ddY_ref`` (p,) the reference acceleration
    [m/s^2, rad/s^2]; ``Kp`` [1/s^2], ``Kd`` [1/s]; ``err`` (p,) receives ``e``. With an exact model the
    node error obeys ``e'' + Kd e' + Kp e = 0``."""
    pose_error_into(target, Y, npos, err)
    acceleration_from_error_into(err, dY_ref, dY, ddY_ref, Kp, Kd, a_cmd)


@njit(cache=True)
def acceleration_from_error_into(err, dY_ref, dY, ddY_ref, Kp, Kd, a_cmd):
    """``a_cmd = ddY_ref + Kd (dY_ref - dY) + Kp err`` (p,) [m/s^2, rad/s^2] from the pose error ``err``
    [m, rad] (:func:`tracking_acceleration_into` after its :func:`pose_error_into`; the leader's
    computed-torque law, :func:`coopctrl.controllers.leader_law.computed_torque_law`)."""
    for a in range(a_cmd.shape[0]):
        a_cmd[a] = ddY_ref[a] + Kd * (dY_ref[a] - dY[a]) + Kp * err[a]


@njit(cache=True)
def leader_target_into(Y_nominal, increment, offset, out):
    """The leader's node target ``out = (Y_nominal + increment) + offset`` (p,) [m, rad]: its nominal node
    pose, the pose increment of its QP share (:func:`pose_increment_into`) and a probe's offset (zeros)."""
    for a in range(out.shape[0]):
        out[a] = Y_nominal[a] + increment[a] + offset[a]


@njit(cache=True)
def leader_acceleration_into(Y_nominal, increment, offset, Y, dY_nominal, dY, ddY_nominal, Kp, Kd, npos, target,
                             err, a_cmd):
    """The leader's commanded node acceleration into ``a_cmd`` (p,): :func:`leader_target_into` into
    ``target``, then :func:`tracking_acceleration_into` toward it along the nominal rates
    ``dY_nominal`` [m/s, rad/s] and acceleration ``ddY_nominal`` [m/s^2, rad/s^2]."""
    leader_target_into(Y_nominal, increment, offset, target)
    tracking_acceleration_into(target, Y, dY_nominal, dY, ddY_nominal, Kp, Kd, npos, err, a_cmd)


@njit(cache=True)
def follower_correction_into(F_cmd, F_seen, integral, T, kp, ki, integral_limit, force_loop, corr):
    """The follower's force PI in wrench units into ``corr`` (p,) [N, N m], updating ``integral`` in place:

    .. math::
        e = F_{cmd} - F_{seen}, \\quad
        I \\leftarrow \\mathrm{clip}(I + e\\,T, -I_{max}, I_{max}), \\quad
        corr = F_{cmd} + k_p e + k_i I

    ``F_cmd`` (p,) the setpoint ``F_i^*`` [N, N m]; ``F_seen`` (p,) the measured wrench; ``integral`` (p,)
    the force-error integral ``I`` [N s, N m s]; ``T`` the control period [s]; ``kp`` [-], ``ki`` [1/s];
    ``integral_limit`` ``I_max`` [N s]. With ``force_loop`` False, ``corr = F_cmd`` and ``integral`` is
    left alone. The follower's target pose is then ``pose_increment(corr) + Y_rigid``."""
    for a in range(corr.shape[0]):
        corr[a] = F_cmd[a]
    if force_loop:
        for a in range(corr.shape[0]):
            e = F_cmd[a] - F_seen[a]
            v = integral[a] + e * T
            if v < -integral_limit:
                v = -integral_limit
            elif v > integral_limit:
                v = integral_limit
            integral[a] = v
            corr[a] = F_cmd[a] + kp * e + ki * v


@njit(cache=True)
def pose_increment_into(spatial, C, F, Y0, Yi, R, v, out):
    """The node pose increment [m, rad] that changes the node's wrench on the object by ``F`` (p,) [N, N m]
    through its grasp compliance ``C`` (p, p, object frame) into ``out`` (p,):
    ``d = C R0^T F``, position ``R0 d[:3]``, angles ``L(A_i)^-1 R_i^T R0 d[3:]`` (spatial, ``R0`` the object's
    rotation at pose ``Y0``, ``A_i`` the node's angles ``Yi[3:6]``); planar ``d = C R(theta0)^T F``, the
    position rotated back. ``R`` (3, 3, 3) and ``v`` (3, 6) scratch. Returns False (angles zero) where
    ``L(A_i)`` is singular (spatial)."""
    if spatial:
        return pose_increment_spatial_into(C, F, Y0[3:6], Yi[3:6], R, v, out)
    pose_increment_planar_into(C, F, Y0[2], out)
    return True


@njit(cache=True)
def follower_acceleration_into(spatial, C, corr, Y0, Y_rigid, Y, dY_ref, dY, ddY_ref, Kp, Kd, npos, R, v, target, err,
                               a_cmd):
    """The follower's commanded node acceleration into ``a_cmd`` (p,): its target
    ``target = pose_increment(corr) + Y_rigid`` (:func:`pose_increment_into` of the PI's output ``corr``
    [N, N m] through the grasp compliance ``C``, at the nominal object pose ``Y0`` and rigid nominal node pose
    ``Y_rigid`` [m, rad]), then :func:`tracking_acceleration_into` toward it along the nominal rates
    ``dY_ref`` and acceleration ``ddY_ref``. ``R``, ``v`` scratch of :func:`pose_increment_into`. Returns
    False (``a_cmd`` not written) where the node's body-rate map is singular."""
    if not pose_increment_into(spatial, C, corr, Y0, Y_rigid, R, v, target):
        return False
    for a in range(target.shape[0]):
        target[a] += Y_rigid[a]
    tracking_acceleration_into(target, Y, dY_ref, dY, ddY_ref, Kp, Kd, npos, err, a_cmd)
    return True


@njit(cache=True)
def posture_torque_into(H, q, dq, q_rest, n, Kp, Kd, out):
    """The damped null-space posture torque of a redundant arm into ``out[:n]`` [N m]:

    .. math:: \\tau_0 = \\bar m \\big(K_p (q_{rest} - q) - K_d \\dot q\\big), \\qquad \\bar m = \\mathrm{tr}(H) / n

    ``H`` (>= n, >= n) the arm's inertia [kg m^2]; ``q``, ``dq``, ``q_rest`` (>= n,) joint positions,
    rates and rest posture [rad, rad/s]; ``Kp = omega_p^2`` [1/s^2], ``Kd = 2 zeta_p omega_p`` [1/s]."""
    tr = 0.0
    for c in range(n):
        tr += H[c, c]
    m_bar = tr / n
    for c in range(n):
        out[c] = m_bar * (Kp * (q_rest[c] - q[c]) - Kd * dq[c])


@njit(cache=True)
def arm_torque_into(contact, n, W, w_free, S, H, h, J, Jdq, a_cmd, q, dq, q_rest, posture_gain, wv, wm, piv, tp, tau):
    """Joint torques ``tau[:n]`` [N m] of an arm of ``n`` joints that give its node the acceleration
    ``a_cmd`` (p,) on the full model (``tau[:p]`` = the node wrench for a contact point, ``contact`` True):

    .. math:: \\tau = H \\ddot q + h + J^T (W a_{cmd} + w_{free} + S) \\; [+\\, P^T \\tau_0], \\qquad
              \\ddot q = J^{-1} (a_{cmd} - \\dot J \\dot q) \\;\\text{or}\\; J^\\# (a_{cmd} - \\dot J \\dot q)

    A redundant arm (``n > p``) adds the posture torque ``tau_0`` of :func:`posture_torque_into` (into
    ``tp``; ``posture_gain = (Kp, Kd)``, ``q``, ``dq``, ``q_rest`` its joints) through the projector
    ``P^T = I - J^T J^{#T}`` with the dynamically consistent inverse ``J^#``
    (:func:`~coopctrl.controllers._kernels.node_torque_redundant_into`); a square arm inverts ``J``
    (:func:`~coopctrl.controllers._kernels.node_torque_into`). The node's terms ``W`` (p, p) [kg, kg m^2],
    ``w_free``, ``S`` (p,) [N, N m] and the arm's ``H``, ``h``, ``J`` (p, >= n), ``Jdq`` (p,) are the plant's
    control terms. ``wv``, ``wm``, ``piv`` scratch (:func:`~coopctrl.controllers._kernels.control_work`).
    Returns False where ``J`` (or ``J N^-1 J^T``) is singular."""
    p = a_cmd.shape[0]
    if not contact and n > p:
        posture_torque_into(H, q, dq, q_rest, n, posture_gain[0], posture_gain[1], tp)
        return node_torque_redundant_into(W, w_free, S, H, h, J, Jdq, a_cmd, tp, n, wv, wm, piv, tau)
    return node_torque_into(W, w_free, S, H, h, J, Jdq, a_cmd, contact, n, wv, wm, piv, tau)
