"""The leader's tracking-error dynamics under computed torque, sampled with a zero-order hold.

With an exact model, the computed torque of :class:`~coopctrl.controllers.LeaderController`
gives the leader node the commanded acceleration, so each pose coordinate of the tracking
error ``e = Y_v - Y_v^N`` is a double integrator driven by the feedback part ``a`` of the
command (docs/model.md s.6):

.. math::
    \\ddot e = a, \\qquad a_k = -K_p e_k - K_d \\dot e_k, \\quad K_p = \\omega_n^2,\\; K_d = 2 \\zeta \\omega_n

where the controller samples ``(e, de)`` every control period ``T`` and holds ``a`` (ZOH).
The sampled double integrator is

.. math::
    \\begin{bmatrix} e \\\\ \\dot e \\end{bmatrix}_{k+1} =
    \\begin{bmatrix} 1 & T \\\\ 0 & 1 \\end{bmatrix} \\begin{bmatrix} e \\\\ \\dot e \\end{bmatrix}_k
    + \\begin{bmatrix} T^2/2 \\\\ T \\end{bmatrix} a_k

so ``(K_p, K_d)`` is exactly a state feedback on it: the design model of the leader gains.
"""

from __future__ import annotations

import numpy as np


def error_dynamics(control_period: float | None = None):
    """The double integrator ``e'' = a`` (continuous, ``control_period=None``) or its ZOH
    sampling with ``dt = control_period`` [s], as a named ``control.StateSpace``
    (states ``e`` [m or rad], ``de``; input ``a`` [m/s^2 or rad/s^2]; output ``e``)."""
    import control

    sys = control.ss([[0.0, 1.0], [0.0, 0.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]],
                     states=["e", "de"], inputs=["a"], outputs=["e"], name="leader_error")
    if control_period is None:
        return sys
    return control.c2d(sys, control_period, method="zoh")


def error_poles(natural_frequency: float, damping_ratio: float, control_period: float | None = None) -> np.ndarray:
    """Closed-loop poles of the tracking error with ``K_p = omega_n^2``, ``K_d = 2 zeta omega_n``:
    ``s`` [rad/s] (continuous) or ``z`` (sampled at ``control_period``)."""
    sys = error_dynamics(control_period)
    K = np.array([[natural_frequency**2, 2.0 * damping_ratio * natural_frequency]])
    return np.linalg.eigvals(np.asarray(sys.A) - np.asarray(sys.B) @ K)
