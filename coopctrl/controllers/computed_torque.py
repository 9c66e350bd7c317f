"""Computed torque on the full cooperative model, in node coordinates (docs/model.md s.4-6).

The laws run in the C++ core (``coopctrl._core``, coopctrl/core/control_laws.h), the ones the loop's tick runs."""

from __future__ import annotations

import numpy as np

from coopctrl._core import arm_torque as _arm_torque
from coopctrl._core import node_torque, pose_error as _pose_error, posture_torque
from plants.cooperative import ContactPoint
from plants.errors import SingularJacobianError


def _vector(name: str, value, size: int | None = None) -> np.ndarray:
    a = np.ascontiguousarray(value, dtype=float)
    if a.ndim != 1 or (size is not None and a.shape[0] != size):
        want = f"({size},)" if size is not None else "(p,)"
        raise ValueError(f"{name}: shape {a.shape}; expected {want}, a node pose or rate [m, rad]")
    return a


def pose_error(Y_target, Y, space: str) -> np.ndarray:
    """``Y_target - Y`` with the angle components wrapped into [-pi, pi) [m, rad]: the C++ core's
    ``pose_error`` (the loop's own)."""
    target = _vector("Y_target", Y_target)
    Yc = _vector("Y", Y, target.shape[0])
    out = np.empty(target.shape[0])
    _pose_error(target, Yc, 3 if space == "spatial" else 2, out)
    return out


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
        """``tau_0`` [N m] at ``terms`` (its ``z``, ``dz``, ``H``), or ``None`` for a square arm: the C++ core's
        ``posture_torque`` (the loop's own)."""
        if not self.active:
            return None
        out = np.empty(self.n)
        posture_torque(np.ascontiguousarray(terms.H[self.index]), np.ascontiguousarray(terms.z[self.slice]),
                       np.ascontiguousarray(terms.dz[self.slice]), self.q_rest, self.n, self.Kp, self.Kd, out)
        return out


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
    :class:`~plants.errors.SingularJacobianError`. In the C++ core: ``coopctrl._core.node_torque``.

    Redundant arm (``n > p``, e.g. a 7-joint arm in space): with ``N = H + J^T W_i J`` (the
    arm-and-node inertia of (177)) and its dynamically consistent generalized inverse
    ``J^# = N^-1 J^T (J N^-1 J^T)^-1``,

    .. math::
        \\ddot q = J^\\# (a_{cmd} - \\dot J \\dot q), \\quad
        \\tau = H \\ddot q + h + J^T (W_i a_{cmd} + w_i) + P^T \\tau_0, \\quad
        P^T = I - J^T J^{\\#T}

    the task torque plus the null-space torque ``P^T tau_0``, which gives the node no
    acceleration (``J N^-1 P^T = 0``). ``tau_posture`` is ``tau_0`` (:class:`PostureTask`;
    ``None`` = 0). In the C++ core: ``coopctrl._core.node_torque``.
    """
    k = i + 1
    arm = plant.arms[i]
    contact = isinstance(arm, ContactPoint)
    n = arm.dof
    redundant = not contact and n > plant.p
    tau_0 = np.ascontiguousarray(tau_posture, dtype=float) if redundant and tau_posture is not None else None
    tau = np.empty(n)
    ok = node_torque(contact, np.ascontiguousarray(terms.W[k]), np.ascontiguousarray(terms.w_free[k]),
                     np.ascontiguousarray(terms.S[k]), np.ascontiguousarray(terms.H[i, :n, :n]),
                     np.ascontiguousarray(terms.h[i, :n]), np.ascontiguousarray(terms.J[i, :, :n]),
                     np.ascontiguousarray(terms.Jdq[i]), np.ascontiguousarray(a_cmd, dtype=float), tau_0, tau)
    if not ok:
        raise SingularJacobianError(f"Jacobian of arm {i} ('{arm.name}')", float("inf"))
    return tau


def arm_torque(plant, terms, i: int, a_cmd, posture: PostureTask) -> np.ndarray:
    """Joint torques [N m] of arm ``i`` that give its node the acceleration ``a_cmd`` (p,) [m/s^2, rad/s^2]
    at ``terms``, the null-space ``posture`` task of a redundant arm included: the C++ core's ``arm_torque``
    (coopctrl/core/control_laws.h), the loop's own (the law of :func:`node_computed_torque`
    with ``tau_posture = posture.torque(terms)``). Raises :class:`~plants.errors.SingularJacobianError` where
    the arm's Jacobian is singular."""
    k = i + 1
    arm = plant.arms[i]
    contact = isinstance(arm, ContactPoint)
    n = arm.dof
    p = plant.p
    a = _vector("a_cmd", a_cmd, p)
    tau = np.empty(max(n, p))
    if posture.active:
        q, dq, q_rest = terms.z[posture.slice], terms.dz[posture.slice], posture.q_rest
        gain = np.array([posture.Kp, posture.Kd])
    else:
        q = dq = q_rest = np.zeros(n)
        gain = np.zeros(2)
    ok = _arm_torque(contact, n, np.ascontiguousarray(terms.W[k]), np.ascontiguousarray(terms.w_free[k]),
                     np.ascontiguousarray(terms.S[k]), np.ascontiguousarray(terms.H[i]),
                     np.ascontiguousarray(terms.h[i]), np.ascontiguousarray(terms.J[i]),
                     np.ascontiguousarray(terms.Jdq[i]), a, np.ascontiguousarray(q), np.ascontiguousarray(dq),
                     np.ascontiguousarray(q_rest, dtype=float), gain, tau)
    if not ok:
        raise SingularJacobianError(f"Jacobian of arm {i} ('{arm.name}')", float("inf"))
    return tau[:p if contact else n].copy()
