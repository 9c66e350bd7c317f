"""Computed torque on the full cooperative model, in node coordinates (docs/model.md s.4-6)."""

from __future__ import annotations

import numpy as np

from coopctrl.controllers._kernels import node_torque, node_torque_redundant
from plants.cooperative import ContactPoint
from plants.errors import SingularJacobianError


def pose_error(Y_target, Y, space: str) -> np.ndarray:
    """``Y_target - Y`` with the angle components wrapped into [-pi, pi) [m, rad]."""
    e = np.asarray(Y_target, dtype=float) - Y
    k = 3 if space == "spatial" else 2
    e[k:] = (e[k:] + np.pi) % (2.0 * np.pi) - np.pi
    return e


#: Null-space posture task of a redundant arm: natural frequency [rad/s] and damping ratio [-].
#: Well below the task loops (tens of rad/s): it only keeps the self-motion (the elbow) quiet.
POSTURE_NATURAL_FREQUENCY = 4.0
POSTURE_DAMPING_RATIO = 1.0


class PostureTask:
    """Damped null-space posture task of a redundant arm (``n > p``) toward a rest posture:

    .. math:: \\tau_0 = \\bar m \\big(\\omega_p^2 (q_{rest} - q) - 2 \\zeta_p \\omega_p \\dot q\\big),
              \\quad \\bar m = \\mathrm{tr}(H) / n

    applied through the null-space projector ``P^T = I - J^T J^{#T}`` of
    :func:`node_computed_torque`. Its equilibrium is ``q_rest - q`` in the range of ``J^T``:
    the configuration of the self-motion manifold nearest to ``q_rest``, the one
    :meth:`~plants.arms.spatial_ik.SpatialInverseKinematics.inverse_kinematics` starts from.
    ``q_rest`` is the arm's rest posture (``arm.rest_posture()``: the scene's ``q_rest``, else
    the middle of the joint limits).
    """

    def __init__(self, plant, index: int, natural_frequency: float = POSTURE_NATURAL_FREQUENCY,
                 damping_ratio: float = POSTURE_DAMPING_RATIO):
        arm = plant.arms[index]
        self.index = index
        self.active = (not isinstance(arm, ContactPoint)) and arm.dof > plant.p
        self.slice = plant.q_slice(index) if self.active else None
        self.n = arm.dof
        self.Kp = natural_frequency**2
        self.Kd = 2.0 * damping_ratio * natural_frequency
        self.q_rest = np.array(arm.rest_posture(), dtype=float) if self.active else None

    def reset(self) -> None:
        """Nothing to forget (kept for the controllers' ``reset``)."""

    def torque(self, terms):
        """``tau_0`` [N m] at ``terms`` (its ``z``, ``dz``, ``H``), or ``None`` for a square arm."""
        if not self.active:
            return None
        q = terms.z[self.slice]
        dq = terms.dz[self.slice]
        n = self.n
        m_bar = float(np.trace(terms.H[self.index, :n, :n])) / n
        return m_bar * (self.Kp * (self.q_rest - q) - self.Kd * dq)


def node_computed_torque(plant, terms, i: int, a_cmd, tau_posture=None) -> np.ndarray:
    """Joint torques that give node ``i + 1`` the acceleration ``a_cmd`` on the full model.

    With the node equation ``W_i Y_i'' + w_i = F_i`` and the arm equation
    ``H q'' + h = tau - J^T F_i`` (166-172):

    .. math::
        \\ddot q = J^{-1} (a_{cmd} - \\dot J \\dot q), \\quad
        F_i = W_i a_{cmd} + w_i, \\quad \\tau = H \\ddot q + h + J^T F_i

    where ``w_i = w_free + S_i`` holds the gyroscopic and gravity terms and the
    interconnection forces at the node (from ``terms``). For a contact point ``tau = F_i``.
    A square arm (``n = p``) inverts ``J``; a singular ``J`` raises
    :class:`~plants.errors.SingularJacobianError`. Compiled in
    :func:`coopctrl.controllers._kernels.node_torque`.

    Redundant arm (``n > p``, e.g. a 7-joint arm in space): with ``N = H + J^T W_i J`` (the
    arm-and-node inertia of (177)) and its dynamically consistent generalized inverse
    ``J^# = N^-1 J^T (J N^-1 J^T)^-1``,

    .. math::
        \\ddot q = J^\\# (a_{cmd} - \\dot J \\dot q), \\quad
        \\tau = H \\ddot q + h + J^T (W_i a_{cmd} + w_i) + P^T \\tau_0, \\quad
        P^T = I - J^T J^{\\#T}

    the task torque plus the null-space torque ``P^T tau_0``, which gives the node no
    acceleration (``J N^-1 P^T = 0``). ``tau_posture`` is ``tau_0`` (:class:`PostureTask`;
    ``None`` = 0). Compiled in
    :func:`coopctrl.controllers._kernels.node_torque_redundant`.
    """
    k = i + 1
    arm = plant.arms[i]
    contact = isinstance(arm, ContactPoint)
    n = arm.dof
    if not contact and n > plant.p:
        q0 = np.zeros(n) if tau_posture is None else np.ascontiguousarray(tau_posture, dtype=float)
        tau, ok = node_torque_redundant(np.ascontiguousarray(terms.W[k]), terms.w_free[k], terms.S[k],
                                        np.ascontiguousarray(terms.H[i, :n, :n]), np.ascontiguousarray(terms.h[i, :n]),
                                        np.ascontiguousarray(terms.J[i, :, :n]), terms.Jdq[i],
                                        np.ascontiguousarray(a_cmd, dtype=float), q0)
        if not ok:
            raise SingularJacobianError(f"Jacobian of arm {i} ('{arm.name}')", float("inf"))
        return tau
    tau, ok = node_torque(terms.W[k], terms.w_free[k], terms.S[k], terms.H[i, :n, :n], terms.h[i, :n],
                          terms.J[i, :, :n], terms.Jdq[i], np.ascontiguousarray(a_cmd, dtype=float), contact)
    if not ok:
        raise SingularJacobianError(f"Jacobian of arm {i} ('{arm.name}')", float("inf"))
    return tau
