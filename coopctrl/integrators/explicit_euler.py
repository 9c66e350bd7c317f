"""Explicit (forward) Euler."""

from __future__ import annotations

from coopctrl.integrators.base import check_damping_ratio, check_omega_max
from coopctrl.integrators.stepping import CompiledScheme


class ExplicitEuler(CompiledScheme):
    """Explicit Euler, order 1.

    .. math::

        x_{k+1} = x_k + h\\, f(t_k, x_k, u_k)

    Stability: the amplification factor on the test equation ``dx/dt = lambda x`` is
    ``R(h lambda) = 1 + h lambda``; the stable region is the disk ``|1 + h lambda| <= 1``
    (centre -1, radius 1), which touches the imaginary axis only at 0. For an undamped oscillator
    of frequency ``omega`` (``lambda = +-i omega``), ``|1 + i h omega| = sqrt(1 + h^2 omega^2) > 1``:
    the amplitude grows at **every** step ``h > 0``, so :meth:`predicted_max_step` is ``0.0``.
    With damping ratio ``zeta`` the mode is stable for ``h <= -2 Re(lambda) / |lambda|^2``, i.e.
    ``h omega <= 2 zeta`` (``zeta <= 1``) or ``h omega <= 2 / (zeta + sqrt(zeta^2 - 1))``
    (``zeta > 1``, set by the faster real eigenvalue).

    One call of ``f`` per step; :meth:`step` runs :mod:`coopctrl.integrators.compiled`.
    """

    name = "euler"
    order = 1
    stability_polynomial = (1.0, 1.0)

    def predicted_max_step(self, omega_max: float, damping_ratio: float = 0.0) -> float:
        """Largest stable step [s] on the oscillator ``(omega_max [rad/s], damping_ratio [-])``
        (``0.0`` undamped: unstable at every step)."""
        return self._mode_max_step(check_omega_max(omega_max), check_damping_ratio(damping_ratio))
