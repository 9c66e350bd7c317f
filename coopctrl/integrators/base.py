"""Abstract base of the fixed-step integrators, and their linear stability analysis.

A plant is a right-hand side ``f(t, x, u) -> dx`` with the first-order state
``x = (z, dz)`` of size ``2 n`` (positions, then velocities) and ``dx = (dz, ddz)``. The input
``u`` is held constant over a step (zero-order hold). ``f`` must return a **new** array on each
call (the integrators keep several evaluations alive at once).

Linear stability. On ``dx/dt = A x`` one step of a scheme is a linear map ``x_{k+1} = M(h) x_k``
(:meth:`Integrator.one_step_matrix`). For the Runge-Kutta family ``M(h) = R(h A)`` with the
scheme's stability function ``R``, so each eigenvalue ``lambda`` of ``A`` is a *mode* amplified by
``|R(h lambda)|`` per step, and the scheme is stable on the mode while ``|R(h lambda)| <= 1``
(:meth:`Integrator.eigenvalue_max_step`). A mode with ``Re(lambda) > 0`` grows in the exact flow
too (a physical instability, e.g. an arm falling under gravity): no step cures it, so it does not
limit the step (:meth:`Integrator.max_stable_step` skips it). ``Re(lambda)`` within
:data:`MARGINAL_REAL_PART` ``|lambda|`` of zero is taken as exactly zero (an undamped mode whose
linearization carries finite-difference noise).
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from typing import Any, Callable

import numpy as np

#: A plant right-hand side ``f(t, x, u) -> dx``: ``t`` in [s], ``x = (z, dz)``, ``dx = (dz, ddz)``.
RightHandSide = Callable[[float, np.ndarray, Any], np.ndarray]

#: ``|Re(lambda)| <= MARGINAL_REAL_PART |lambda|`` counts as ``Re(lambda) = 0`` [-]: an undamped mode.
#: The plant's central-difference Jacobian is accurate to ~1e-9 relative; 1e-6 leaves margin and
#: is far below any physical damping ratio worth modelling.
MARGINAL_REAL_PART = 1e-6


#: ``|lambda| <= ZERO_MODE max |lambda|`` is a zero mode (period beyond hours when the fastest
#: mode is at hundreds of rad/s) [-]; see :func:`split_modes`.
ZERO_MODE = 1e-6


def check_omega_max(omega_max: float) -> float:
    """Validate ``omega_max`` [rad/s] (finite, >= 0) and return it as a float."""
    omega = float(omega_max)
    if not math.isfinite(omega) or omega < 0.0:
        raise ValueError(
            f"omega_max = {omega_max!r} is invalid: expected a finite angular frequency >= 0 [rad/s]"
        )
    return omega


def check_damping_ratio(damping_ratio: float) -> float:
    """Validate a damping ratio ``zeta`` [-] (finite, >= 0) and return it as a float."""
    zeta = float(damping_ratio)
    if not math.isfinite(zeta) or zeta < 0.0:
        raise ValueError(f"damping_ratio = {damping_ratio!r} is invalid: expected a finite ratio >= 0 [-]")
    return zeta


def mode_eigenvalues(omega: float, zeta: float) -> tuple[complex, complex]:
    """The two eigenvalues [1/s] of ``ddz + 2 zeta omega dz + omega^2 z = 0``.

    ``lambda = omega (-zeta +- i sqrt(1 - zeta^2))`` (underdamped) or
    ``omega (-zeta +- sqrt(zeta^2 - 1))`` (overdamped, both real).
    """
    if zeta < 1.0:
        s = math.sqrt(1.0 - zeta * zeta)
        return complex(-zeta * omega, s * omega), complex(-zeta * omega, -s * omega)
    s = math.sqrt(zeta * zeta - 1.0)
    return complex(omega * (-zeta - s), 0.0), complex(omega * (-zeta + s), 0.0)


def split_modes(eigenvalues) -> tuple[np.ndarray, float]:
    """Split eigenvalues of ``A`` into the modes that can limit a step and the physical growth rate.

    Eigenvalues with ``|lambda| <= ZERO_MODE * max |lambda|`` are zero modes (rigid-body motions
    of a free-floating part, whose finite-difference eigenvalues are noise of order 1e-6 rad/s):
    ``R(0) = 1``, they never limit a step and are dropped.

    Returns:
        ``(modes, sigma)``: the eigenvalues with ``Re(lambda) <= MARGINAL_REAL_PART |lambda|``
        (those within the margin have their real part set to 0: undamped), and ``sigma`` [1/s],
        the largest real part of the others (physically unstable modes), 0 if none.
    """
    lam = np.asarray(eigenvalues, dtype=complex).ravel()
    mag = np.abs(lam)
    if lam.size:
        keep = mag > ZERO_MODE * mag.max()
        lam, mag = lam[keep], mag[keep]
    unstable = lam.real > MARGINAL_REAL_PART * mag
    sigma = float(lam.real[unstable].max()) if np.any(unstable) else 0.0
    modes = lam[~unstable].copy()
    marginal = np.abs(modes.real) <= MARGINAL_REAL_PART * np.abs(modes)
    modes[marginal] = 1j * modes[marginal].imag
    return modes, sigma


def spectral_radius(M: np.ndarray) -> float:
    """``max |eig(M)|`` [-]."""
    return float(np.max(np.abs(np.linalg.eigvals(M)))) if M.size else 0.0


class FrozenSettings:
    """Mixin of the built-in schemes: each public setting (``rtol``, ``max_iterations``, ...) is set once,
    validated, by the constructor, and never changed afterwards (a run's plan is made from them). A
    different setting is a new object: ``get_integrator(name, rtol=...)``."""

    def __setattr__(self, name: str, value) -> None:
        if not name.startswith("_") and name in self.__dict__:
            raise AttributeError(f"{type(self).__name__}.{name} is a frozen setting (now {self.__dict__[name]!r}): "
                                 f"make a new scheme, get_integrator({getattr(self, 'name', '')!r}, {name}=...)")
        object.__setattr__(self, name, value)


class Integrator(ABC):
    """One fixed-step scheme for ``dx/dt = f(t, x, u)`` with ``u`` held over the step.

    Attributes:
        name: Registry name (``"rk4"``).
        order: Order of global accuracy [-].
        stability_polynomial: Coefficients ``(c_0, c_1, ...)`` of the stability function
            ``R(z) = sum_k c_k z^k`` of an explicit Runge-Kutta scheme, or ``None``.
    """

    name: str = ""
    order: int = 0
    stability_polynomial: tuple[float, ...] | None = None

    @abstractmethod
    def step(self, f: RightHandSide, t: float, x: np.ndarray, u: Any, h: float) -> np.ndarray:
        """Advance the state by one step.

        Args:
            f: Right-hand side ``f(t, x, u) -> dx``.
            t: Time at the start of the step in [s].
            x: State ``(z, dz)`` at ``t``, a 1-D float64 array of size ``2 n`` (not modified).
            u: Input, held constant over the step.
            h: Step in [s].

        Returns:
            A new array: the state at ``t + h``.
        """

    @abstractmethod
    def predicted_max_step(self, omega_max: float) -> float:
        """Largest stable step [s] for an undamped oscillator of frequency ``omega_max`` [rad/s].

        ``math.inf`` when the scheme is unconditionally stable (or ``omega_max = 0``), ``0.0``
        when it is unstable at every step. The four built-in schemes also take an optional
        ``damping_ratio`` (the oscillator ``ddz + 2 zeta omega dz + omega^2 z = 0``).
        """

    def reset(self) -> None:
        """Forget any state cached between steps (no-op for the explicit schemes)."""

    # ------------------------------------------------------------------ linear stability
    def stability_function(self, z):
        """``R(z)``: the factor one step multiplies the solution of ``dx/dt = lambda x`` by, ``z = h lambda``.

        Raises:
            NotImplementedError: when the one-step map is not a function of ``h lambda`` alone
                (symplectic Euler); use :meth:`one_step_matrix` then.
        """
        if self.stability_polynomial is None:
            raise NotImplementedError(f"{type(self).__name__} has no scalar stability function")
        return np.polynomial.polynomial.polyval(z, self.stability_polynomial)

    def one_step_matrix(self, A, h: float) -> np.ndarray:
        """The matrix ``M`` of one step [s] ``h`` on ``dx/dt = A x``: ``x_{k+1} = M x_k``.

        Built by applying :meth:`step` itself to the columns of the identity (so it is the
        scheme as implemented, not a formula for it); ``A`` is ``(2 n, 2 n)`` in the state
        order ``(z, dz)``.
        """
        A = np.asarray(A, dtype=float)
        n = A.shape[0]
        f = lambda t, x, u: A @ x  # noqa: E731 - a new array per call, as step() requires
        self.reset()
        M = np.empty((n, n))
        for j in range(n):
            e = np.zeros(n)
            e[j] = 1.0
            M[:, j] = self.step(f, 0.0, e, None, float(h))
        self.reset()
        return M

    def eigenvalue_max_step(self, lam: complex) -> float:
        """Largest step [s] ``h`` such that ``|R(s lambda)| <= 1`` for every ``0 < s <= h``.

        For an explicit Runge-Kutta scheme with ``y = s |lambda|`` and ``e = lambda / |lambda|``,
        ``P(y) = |R(y e)|^2 - 1`` is a real polynomial with ``P(0) = 0``; the limit is its first
        positive root where it turns positive (``math.inf`` for ``lambda = 0``, ``0.0`` when it is
        positive right away, as for explicit Euler on an undamped mode). Eigenvalues within
        :data:`MARGINAL_REAL_PART` of the imaginary axis are put on it.

        Raises:
            NotImplementedError: for a scheme without a stability polynomial.
        """
        if self.stability_polynomial is None:
            raise NotImplementedError(f"{type(self).__name__} has no scalar stability function")
        return _polynomial_ray_limit(self.stability_polynomial, complex(lam))

    def max_stable_step(self, A) -> float:
        """Largest stable step [s] on the linear system ``dx/dt = A x`` (e.g. a plant's linearization).

        The minimum of :meth:`eigenvalue_max_step` over the eigenvalues of ``A`` that are not
        physically unstable (:func:`split_modes`). ``math.inf`` if no mode limits the step,
        ``0.0`` if the scheme is unstable on some mode at every step. A scheme without a scalar
        stability function falls back to :meth:`predicted_max_step` at ``max |lambda|``.
        """
        A = np.asarray(A, dtype=float)
        modes, _ = split_modes(np.linalg.eigvals(A) if A.size else np.zeros(0))
        try:
            return min((self.eigenvalue_max_step(lam) for lam in modes), default=math.inf)
        except NotImplementedError:
            w = float(np.max(np.abs(modes))) if modes.size else 0.0
            return self.predicted_max_step(w)

    def _mode_max_step(self, omega: float, zeta: float) -> float:
        """:meth:`eigenvalue_max_step` over both eigenvalues of the oscillator ``(omega, zeta)``."""
        if omega == 0.0:
            return math.inf
        return min(self.eigenvalue_max_step(lam) for lam in mode_eigenvalues(omega, zeta))

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


def _polynomial_ray_limit(coefficients, lam: complex) -> float:
    """First ``h > 0`` where ``|R(h lambda)|`` exceeds 1, for ``R(z) = sum_k c_k z^k`` (see
    :meth:`Integrator.eigenvalue_max_step`)."""
    r = abs(lam)
    if r == 0.0 or not math.isfinite(r):
        return math.inf if r == 0.0 else 0.0
    e = lam / r
    if abs(e.real) <= MARGINAL_REAL_PART:
        e = complex(0.0, 1.0 if e.imag >= 0 else -1.0)
    c = np.asarray(coefficients, dtype=float)
    a = c * e ** np.arange(c.size)  # R(y e) = sum a_k y^k
    p = np.convolve(a, np.conj(a)).real  # |R(y e)|^2
    p[0] -= 1.0
    q = p[1:]  # P(y) / y
    q = np.where(np.abs(q) <= 1e-14 * np.max(np.abs(q)), 0.0, q)
    nz = np.flatnonzero(q)
    if nz.size == 0:
        return math.inf
    if q[nz[0]] > 0.0:  # P > 0 right after 0: unstable at every step
        return 0.0
    roots = np.roots(q[::-1])
    candidates = sorted(float(z.real) for z in roots if z.real > 0.0 and abs(z.imag) <= 1e-9 * max(1.0, abs(z)))
    poly = np.polynomial.polynomial.polyval
    for y in candidates:
        if poly(y * (1.0 + 1e-9), q) > 0.0:
            return y / r
    return math.inf


#: Relative excess of the one-step spectral radius over the exact flow's growth ``exp(h sigma)``
#: still counted as stable by :func:`matrix_max_step` [-]: above the eigenvalue solver's error on a
#: defective pair (``~ sqrt(eps)`` ~ 1.5e-8), far below the growth of an unstable step.
GROWTH_TOLERANCE = 1e-6


def without_static_instability(A) -> np.ndarray:
    """``A = [[0, I], [A_21, A_22]]`` with the negative stiffnesses removed.

    ``A_21 = -Gamma^-1 K`` has the eigenvalues ``-omega^2``; a positive one is a static
    instability (``omega^2 < 0``: gravity on the arms, a buckling grasp). They are set to zero,
    ``A_21 = V diag(min(-omega^2, 0)) V^-1``, so that the only growth left is numerical. The
    velocity block ``A_22`` (damping) is kept.
    """
    A = np.array(A, dtype=float)
    n = A.shape[0] // 2
    ev, V = np.linalg.eig(A[n:, :n])
    if np.any(ev.real > 0.0):
        ev = np.where(ev.real > 0.0, 0.0, ev)
        A[n:, :n] = (V @ np.diag(ev) @ np.linalg.inv(V)).real
    return A


def matrix_max_step(scheme: Integrator, A, rtol: float = 1e-6, max_h_omega: float = 100.0) -> float:
    """Largest stable step [s] of ``scheme`` on ``dx/dt = A x`` from its one-step matrix.

    For schemes whose one-step map is not a function of ``h A`` (symplectic Euler), the modes of
    ``A`` are not those of ``M(h)``, so the physically unstable ones cannot be skipped one by one.
    They are removed from ``A`` first (:func:`without_static_instability`); a step then counts
    as stable when

    .. math:: \\rho(M(h)) \\le e^{h \\sigma} (1 + \\mathrm{GROWTH\\_TOLERANCE})

    with ``sigma`` the growth rate of what physical instability is left (:func:`split_modes`,
    normally 0). Scanned upwards from ``h = 0.1 / omega`` (``omega = max |lambda|``) by factors of
    1.05, then bisected to ``rtol``; ``math.inf`` if still stable at ``h omega = max_h_omega``.
    """
    A = without_static_instability(A)
    modes, sigma = split_modes(np.linalg.eigvals(A) if A.size else np.zeros(0))
    w = float(np.max(np.abs(modes))) if modes.size else 0.0
    if w == 0.0:
        return math.inf

    def stable(h):
        return spectral_radius(scheme.one_step_matrix(A, h)) <= math.exp(h * sigma) * (1.0 + GROWTH_TOLERANCE)

    lo = 0.1 / w
    if not stable(lo):
        hi, lo = lo, 0.0
    else:
        hi = lo * 1.05
        while stable(hi):
            lo, hi = hi, hi * 1.05
            if hi * w > max_h_omega:
                return math.inf
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if stable(mid):
            lo = mid
        else:
            hi = mid
    return lo
