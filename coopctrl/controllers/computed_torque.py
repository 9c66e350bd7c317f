"""Computed torque on the full cooperative model, in node coordinates (MODEL.md s.4-6)."""

from __future__ import annotations

import numpy as np

from coopctrl.controllers._kernels import node_torque
from plants.cooperative import ContactPoint
from plants.errors import SingularJacobianError


def pose_error(Y_target, Y, space: str) -> np.ndarray:
    """``Y_target - Y`` with the angle components wrapped into [-pi, pi) [m, rad]."""
    e = np.asarray(Y_target, dtype=float) - Y
    k = 3 if space == "spatial" else 2
    e[k:] = (e[k:] + np.pi) % (2.0 * np.pi) - np.pi
    return e


def node_computed_torque(plant, terms, i: int, a_cmd) -> np.ndarray:
    """Joint torques that give node ``i + 1`` the acceleration ``a_cmd`` on the full model.

    With the node equation ``W_i Y_i'' + w_i = F_i`` and the arm equation
    ``H q'' + h = tau - J^T F_i`` (166-172):

    .. math::
        \\ddot q = J^{-1} (a_{cmd} - \\dot J \\dot q), \\quad
        F_i = W_i a_{cmd} + w_i, \\quad \\tau = H \\ddot q + h + J^T F_i

    where ``w_i = w_free + S_i`` holds the gyroscopic and gravity terms and the
    interconnection forces at the node (from ``terms``). For a contact point ``tau = F_i``.
    Arms must be square (``n = p``: the Puma in space, the 3R arm in the plane); a singular
    ``J`` raises :class:`~plants.errors.SingularJacobianError`. Compiled in
    :func:`coopctrl.controllers._kernels.node_torque`.
    """
    k = i + 1
    arm = plant.arms[i]
    contact = isinstance(arm, ContactPoint)
    n = arm.dof
    tau, ok = node_torque(terms.W[k], terms.w_free[k], terms.S[k], terms.H[i, :n, :n], terms.h[i, :n],
                          terms.J[i, :, :n], terms.Jdq[i], np.ascontiguousarray(a_cmd, dtype=float), contact)
    if not ok:
        raise SingularJacobianError(f"Jacobian of arm {i} ('{arm.name}')", float("inf"))
    return tau
