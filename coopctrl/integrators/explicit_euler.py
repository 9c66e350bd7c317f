"""Explicit (forward) Euler."""

from __future__ import annotations

import math

from coopctrl.integrators.base import Integrator, check_omega_max


class ExplicitEuler(Integrator):
    """Explicit Euler, order 1.

    .. math::

        x_{k+1} = x_k + h\\, f(t_k, x_k, u_k)

    Stability: the amplification factor on the test equation ``dx/dt = lambda x`` is
    ``R(h lambda) = 1 + h lambda``; the stable region is the disk ``|1 + h lambda| <= 1``
    (centre -1, radius 1), which touches the imaginary axis only at 0. For an undamped oscillator
    of frequency ``omega`` (``lambda = +-i omega``), ``|1 + i h omega| = sqrt(1 + h^2 omega^2) > 1``:
    the amplitude grows at **every** step ``h > 0``, so :meth:`predicted_max_step` is ``0.0``.
    (With damping ratio ``zeta`` the scheme is stable for ``h <= 2 zeta / omega``.)

    One call of ``f`` per step.
    """

    name = "euler"
    order = 1

    def step(self, f, t, x, u, h):
        dx = f(t, x, u)
        dx *= h
        dx += x
        return dx

    def predicted_max_step(self, omega_max: float) -> float:
        return math.inf if check_omega_max(omega_max) == 0.0 else 0.0
