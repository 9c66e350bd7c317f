"""Semi-implicit (symplectic) Euler."""

from __future__ import annotations

import math

import numpy as np

from coopctrl.integrators.base import check_damping_ratio, check_omega_max, matrix_max_step
from coopctrl.integrators.stepping import CompiledScheme


class SymplecticEuler(CompiledScheme):
    """Semi-implicit (symplectic) Euler, order 1.

    With ``x = (z, dz)`` split by halves and ``ddz`` the second half of ``f``:

    .. math::

        \\dot z_{k+1} = \\dot z_k + h\\, \\ddot z(t_k, z_k, \\dot z_k, u_k), \\qquad
        z_{k+1} = z_k + h\\, \\dot z_{k+1}

    ``f`` is called once per step; its first half (``dz``) is not used, the new velocity is
    (:meth:`step` runs :mod:`coopctrl.integrators.compiled`).

    Stability: for an undamped oscillator ``ddz = -omega^2 z`` the one-step matrix is
    ``[[1 - h^2 omega^2, h], [-h omega^2, 1]]`` with determinant 1 and trace
    ``2 - h^2 omega^2``; it is stable (eigenvalues on the unit circle, a modified quadratic
    energy is conserved, no drift) for ``h omega < 2`` and unstable for ``h omega >= 2``
    (at ``h omega = 2`` a double eigenvalue -1 gives linear growth). Hence
    :meth:`predicted_max_step` is ``2 / omega_max``. The scheme is symplectic for
    ``ddz`` independent of ``dz``.

    With damping, ``ddz = -omega^2 z - 2 zeta omega dz``, the one-step matrix on ``(z, dz)`` is
    ``[[1 - c^2, h (1 - 2 zeta c)], [-h omega^2, 1 - 2 zeta c]]`` with ``c = h omega``: determinant
    ``1 - 2 zeta c``, trace ``2 - c^2 - 2 zeta c``. Its eigenvalues are in the unit disk iff
    ``|det| <= 1`` and ``|trace| <= 1 + det`` (Jury), i.e. ``c^2 + 4 zeta c <= 4``:

    .. math:: h \\omega \\le \\frac{2}{\\zeta + \\sqrt{1 + \\zeta^2}}

    (2 undamped, 0.83 at ``zeta = 1``, ``-> 1 / zeta`` for heavy damping: the explicit velocity
    update of a pure damper ``2 zeta omega``). Damping *lowers* this scheme's limit. The map is
    not a function of ``h lambda`` alone, so on a linearization :meth:`max_stable_step` uses the
    spectral radius of the one-step matrix (:func:`~coopctrl.integrators.base.matrix_max_step`).
    """

    name = "symplectic_euler"
    order = 1

    def predicted_max_step(self, omega_max: float, damping_ratio: float = 0.0) -> float:
        """``2 / (omega (zeta + sqrt(1 + zeta^2)))`` [s] for the oscillator ``(omega_max [rad/s],
        damping_ratio [-])``."""
        omega = check_omega_max(omega_max)
        zeta = check_damping_ratio(damping_ratio)
        if omega == 0.0:
            return math.inf
        return 2.0 / (omega * (zeta + math.sqrt(1.0 + zeta * zeta)))

    def one_step_matrix(self, A, h: float) -> np.ndarray:
        """``[[I + h^2 A_21, h (I + h A_22)], [h A_21, I + h A_22]]`` for ``A = [[., .], [A_21, A_22]]``
        (the first half of ``A``, ``dz``, is not used by the scheme)."""
        A = np.asarray(A, dtype=float)
        n = A.shape[0] // 2
        A21, A22 = A[n:, :n], A[n:, n:]
        V = np.eye(n) + h * A22
        M = np.empty_like(A)
        M[:n, :n] = np.eye(n) + h * h * A21
        M[:n, n:] = h * V
        M[n:, :n] = h * A21
        M[n:, n:] = V
        return M

    def max_stable_step(self, A) -> float:
        """Largest stable step [s] on ``dx/dt = A x`` by the spectral radius of the one-step matrix
        (:func:`~coopctrl.integrators.base.matrix_max_step`)."""
        return matrix_max_step(self, A)
