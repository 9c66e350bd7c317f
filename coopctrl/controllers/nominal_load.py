"""The external load: the wrench the arms must supply to move the object along its nominal path."""

from __future__ import annotations

import numpy as np

from plants.frames import body_rate_map, body_rate_map_dot, rotation_zyx


def required_object_wrench(space: str, mass: float, inertia, gravity, Y0, dY0, ddY0) -> np.ndarray:
    """``w_N`` (docs/model.md s.6): the total contact wrench about the object's MC, world frame.

    .. math::
        w_N = \\begin{bmatrix} m_0 (\\ddot r_0 - g) \\\\
              R_0 (I_0 \\dot\\omega + \\omega \\times I_0 \\omega) \\end{bmatrix}, \\quad
        \\omega = L(A_0) \\dot A_0, \\; \\dot\\omega = L \\ddot A_0 + \\dot L \\dot A_0

    (body rates, principal inertia ``I_0``). Planar: ``(m_0 (x'' - g_x), m_0 (z'' - g_z), I_0 theta'')``.

    Args:
        space: ``"spatial"`` or ``"planar"``.
        mass: Object mass [kg]; inertia: principal moments [kg m^2]; gravity: vector [m/s^2].
        Y0, dY0, ddY0: Nominal object pose, rate and acceleration.
    """
    if space == "planar":
        return np.array([mass * (ddY0[0] - gravity[0]), mass * (ddY0[1] - gravity[1]), inertia[0] * ddY0[2]])
    A, dA, ddA = Y0[3:], dY0[3:], ddY0[3:]
    L = body_rate_map(A)
    w = L @ dA
    dw = L @ ddA + body_rate_map_dot(A, dA) @ dA
    I = np.asarray(inertia, dtype=float)
    Iw = I * w
    torque_body = I * dw + np.array([w[1] * Iw[2] - w[2] * Iw[1], w[2] * Iw[0] - w[0] * Iw[2], w[0] * Iw[1] - w[1] * Iw[0]])
    return np.concatenate([mass * (np.asarray(ddY0[:3]) - gravity), rotation_zyx(A) @ torque_body])
