"""Classic fourth-order Runge-Kutta."""

from __future__ import annotations

import math

from coopctrl.integrators.base import check_damping_ratio, check_omega_max
from coopctrl.integrators.stepping import CompiledScheme

#: Stability limit of RK4 on the imaginary axis: ``|R(i y)| <= 1`` iff ``|y| <= 2 sqrt(2)``.
RK4_IMAGINARY_AXIS_LIMIT = 2.0 * math.sqrt(2.0)
#: Stability limit of RK4 on the negative real axis: ``|R(-y)| <= 1`` iff ``0 <= y <= 2.785293563``.
RK4_REAL_AXIS_LIMIT = 2.785293563405282


class RungeKutta4(CompiledScheme):
    """Classic Runge-Kutta, order 4.

    .. math::

        k_1 = f(t, x), \\; k_2 = f(t + h/2, x + h k_1 / 2), \\;
        k_3 = f(t + h/2, x + h k_2 / 2), \\; k_4 = f(t + h, x + h k_3), \\\\
        x_{k+1} = x_k + h (k_1 + 2 k_2 + 2 k_3 + k_4) / 6

    with ``u`` held over the step (four calls of ``f``; :meth:`step` runs
    :mod:`coopctrl.integrators.compiled`).

    Stability: ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24``. On the **imaginary** axis (undamped
    oscillator, ``z = i h omega``) ``|R(i y)|^2 = 1 - y^6/72 + y^8/576``, so the scheme is
    stable (slightly dissipative) for ``h omega <= 2 sqrt(2) ~= 2.8284`` and unstable beyond;
    :meth:`predicted_max_step` is ``2 sqrt(2) / omega_max``. On the negative **real** axis
    (pure damping, ``z = -h / tau``) the limit is ``h / tau <= 2.785293563`` (where
    ``R(-y) = 1``), see :data:`RK4_REAL_AXIS_LIMIT`; do not confuse the two limits. In between
    (a damped mode, ``lambda = omega (-zeta +- i sqrt(1 - zeta^2))``) the limit is the first root
    of ``|R(h lambda)| = 1`` along the ray (:meth:`eigenvalue_max_step`): ``h omega`` stays within
    2.6 to 2.96 for every ``zeta`` in [0, 1] (2.83 at 0, 2.96 at 0.15, 2.62 at 0.5, 2.785 at 1);
    above ``zeta = 1`` the faster real eigenvalue sets it (``h |lambda| <= 2.785``).
    """

    name = "rk4"
    order = 4
    stability_polynomial = (1.0, 1.0, 1.0 / 2.0, 1.0 / 6.0, 1.0 / 24.0)

    def predicted_max_step(self, omega_max: float, damping_ratio: float = 0.0) -> float:
        """Largest stable step [s] on the oscillator ``(omega_max [rad/s], damping_ratio [-])``."""
        omega = check_omega_max(omega_max)
        zeta = check_damping_ratio(damping_ratio)
        if omega == 0.0:
            return math.inf
        if zeta == 0.0:
            return RK4_IMAGINARY_AXIS_LIMIT / omega
        return self._mode_max_step(omega, zeta)
