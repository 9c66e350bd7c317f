"""The load-distribution QP's contact-dependent inputs in numpy, for the loaded start (before the first tick).

- :func:`contact_normals`: each contact node's inward normal (its frame's approach axis), for the
  ``min_grip`` and ``friction`` families;
- :func:`torque_model`: the ``torque_limits`` family's rows ``tau_i = Jg_i^T F_i + bias_i`` at the
  nominal node accelerations, planned within :data:`TORQUE_HEADROOM` of each joint's limit.

(The compiled tick fills the same rows in :mod:`coopctrl.load_distribution.assembly`.)
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.controllers.computed_torque import task_acceleration
from plants.cooperative import ContactPoint
from plants.frames import body_rate_map, rotation_zyx

#: Fraction of each joint torque limit the load-distribution QP may plan with [-].
TORQUE_HEADROOM = 0.9


def qp_torque_limits(plant) -> list[np.ndarray]:
    """Each arm's torque limits [N m] the QP plans with: ``TORQUE_HEADROOM * tau_max``; the applied
    torques are saturated at ``tau_max`` itself (actuators), leaving the rest for the feedback terms."""
    return [TORQUE_HEADROOM * np.asarray(a.tau_max, dtype=float) for a in plant.arms]


def contact_normals(plant, terms) -> np.ndarray:
    """Inward contact normals (m, npos): each node's approach axis (its frame's x axis), from the
    node poses ``terms.Y`` [m, rad]."""
    Y = terms.Y
    spatial = plant.space == "spatial"
    out = np.empty((plant.arm_count, 3 if spatial else 2))
    for i in range(plant.arm_count):
        if spatial:
            out[i] = rotation_zyx(Y[i + 1, 3:6])[:, 0]
        else:
            out[i] = (math.cos(Y[i + 1, 2]), math.sin(Y[i + 1, 2]))
    return out


def torque_model(plant, terms, ddYn) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """QP torque-limit rows ``(jacobians, biases)``: ``tau_i = Jg_i^T F_i + bias_i`` [N m] with the nominal
    node accelerations ``ddYn`` ((m+1, p) [m/s^2, rad/s^2]); ``Jg_i`` maps the joint rates to the node's
    world twist, ``bias_i = H_i qdd_i + h_i + J_i^T (W_i ddYn_i + w_free_i)`` with ``qdd_i`` the joint
    acceleration that tracks ``ddYn_i``."""
    jac, bias = [], []
    spatial = plant.space == "spatial"
    for i, arm in enumerate(plant.arms):
        k = i + 1
        n = arm.dof
        if isinstance(arm, ContactPoint):
            jac.append(np.eye(plant.p))
            bias.append(terms.W[k] @ ddYn[k] + terms.w_free[k])
            continue
        J = terms.J[i, :, :n]
        if spatial:
            Ai = terms.Y[k, 3:6]
            Jg = J.copy()
            Jg[3:] = rotation_zyx(Ai) @ body_rate_map(Ai) @ J[3:]
        else:
            Jg = J
        try:
            qdd = task_acceleration(terms, i, n, ddYn[k] - terms.Jdq[i])  # J^-1, or J^# if redundant
        except np.linalg.LinAlgError:
            qdd = np.zeros(n)
        jac.append(Jg)
        bias.append(terms.H[i, :n, :n] @ qdd + terms.h[i, :n] + J.T @ (terms.W[k] @ ddYn[k] + terms.w_free[k]))
    return jac, bias
