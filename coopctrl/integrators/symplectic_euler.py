"""Semi-implicit (symplectic) Euler."""

from __future__ import annotations

import math

import numpy as np

from coopctrl.integrators.base import Integrator, check_omega_max


class SymplecticEuler(Integrator):
    """Semi-implicit (symplectic) Euler, order 1.

    With ``x = (z, dz)`` split by halves and ``ddz`` the second half of ``f``:

    .. math::

        \\dot z_{k+1} = \\dot z_k + h\\, \\ddot z(t_k, z_k, \\dot z_k, u_k), \\qquad
        z_{k+1} = z_k + h\\, \\dot z_{k+1}

    ``f`` is called once per step; its first half (``dz``) is not used, the new velocity is.

    Stability: for an undamped oscillator ``ddz = -omega^2 z`` the one-step matrix is
    ``[[1 - h^2 omega^2, h], [-h omega^2, 1]]`` with determinant 1 and trace
    ``2 - h^2 omega^2``; it is stable (eigenvalues on the unit circle, a modified quadratic
    energy is conserved, no drift) for ``h omega < 2`` and unstable for ``h omega >= 2``
    (at ``h omega = 2`` a double eigenvalue -1 gives linear growth). Hence
    :meth:`predicted_max_step` is ``2 / omega_max``. The scheme is symplectic for
    ``ddz`` independent of ``dz``.
    """

    name = "symplectic_euler"
    order = 1

    def step(self, f, t, x, u, h):
        n = x.shape[0] // 2
        ddz = f(t, x, u)[n:]
        x_next = np.empty_like(x)
        dz_next = x_next[n:]
        np.multiply(ddz, h, out=dz_next)
        dz_next += x[n:]
        z_next = x_next[:n]
        np.multiply(dz_next, h, out=z_next)
        z_next += x[:n]
        return x_next

    def predicted_max_step(self, omega_max: float) -> float:
        omega = check_omega_max(omega_max)
        return math.inf if omega == 0.0 else 2.0 / omega
