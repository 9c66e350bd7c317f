"""Implicit midpoint rule solved by simplified Newton."""

from __future__ import annotations

import math

import numpy as np

from coopctrl.errors import DivergenceError
from coopctrl.integrators.base import MARGINAL_REAL_PART, Integrator, check_damping_ratio, check_omega_max

_EPS = np.finfo(float).eps
_SQRT_EPS = math.sqrt(_EPS)


class NewtonConvergenceError(DivergenceError):
    """The Newton iteration of an implicit step did not converge.

    Attributes:
        time: Time [s] at the start of the failed step.
        quantity: ``"Newton correction"``.
        value: Max-norm of the last Newton correction of the state (same units as ``x``).
        suggested_step: Half the step that failed [s].
        iterations: Number of Newton iterations performed.
        step: The step [s] that failed.
    """

    def __init__(self, time: float, value: float, iterations: int, step: float):
        self.time = time
        self.quantity = "Newton correction"
        self.value = value
        self.suggested_step = 0.5 * step
        self.iterations = iterations
        self.step = step
        Exception.__init__(
            self,
            f"implicit midpoint: Newton did not converge at t = {time:.6g} s with h = {step:.3g} s "
            f"after {iterations} iterations (last correction {value:.3g}); reduce the step "
            f"(try {0.5 * step:.3g} s), raise max_iterations, or check the plant for a "
            "non-finite or discontinuous right-hand side",
        )


class ImplicitMidpoint(Integrator):
    """Implicit midpoint rule, order 2, A-stable and symplectic.

    .. math::

        x_{k+1} = x_k + h\\, f\\!\\left(t_k + \\tfrac h2,\\; \\tfrac{x_k + x_{k+1}}{2},\\; u_k\\right)

    solved for the midpoint slope ``k = (x_{k+1} - x_k) / h`` by **simplified Newton**:
    ``G(k) = k - f(t + h/2, x_k + h k / 2, u) = 0`` with the iteration matrix
    ``M = (I - h/2 J)^-1``, ``J = df/dx``. ``J`` is the plant's analytic ``jac(t, x, u)`` when
    ``f`` (or the object ``f`` is bound to) has one, else forward finite differences
    (``2 n`` extra calls of ``f``). ``M`` is kept across iterations and across steps while
    Newton converges fast (contraction rate at most ``reuse_rate``); it is refreshed at the
    current iterate when convergence slows, and when ``f``, ``h`` or the state size change. Convergence:
    ``h max|dk| <= atol + rtol max(max|x_k|, h max|k|)``, or the round-off floor of ``f``: with a
    fresh Jacobian the correction stops shrinking (rate above 1/2) while already below
    ``sqrt(eps) max(max|x_k|, h max|k|)`` (a very stiff spring, ``k / m ~ 1e12``, turns the last bits of
    the positions into accelerations that no Newton step can reduce further). Failure raises
    :class:`NewtonConvergenceError` (an :class:`ArithmeticError`).

    Stability: ``R(z) = (1 + z/2) / (1 - z/2)``; ``|R(z)| <= 1`` on the whole closed left
    half-plane (A-stable), ``|R(i y)| = 1`` on the imaginary axis: an undamped oscillator keeps
    its amplitude at any step, so :meth:`predicted_max_step` is ``math.inf``. The scheme is
    symplectic and conserves every quadratic invariant exactly (up to the Newton tolerance),
    e.g. the energy of a linear oscillator. Accuracy still needs ``h`` small against the time
    scales of interest (phase error ``~ (h omega)^2 / 24`` per radian).

    The cached iteration matrix is the only state; :meth:`reset` drops it. Use one instance
    per simulation.

    Args:
        rtol: Relative Newton tolerance [-].
        atol: Absolute Newton tolerance, in the units of ``x``.
        max_iterations: Newton iterations allowed per step.
        reuse_rate: Largest contraction rate [-] ``|dk_j| / |dk_(j-1)|`` at which ``M`` is kept,
            within the step and for the next one; above it the Jacobian is re-evaluated at the
            current iterate (full Newton in the worst case).
    """

    name = "implicit_midpoint"
    order = 2

    def __init__(self, rtol: float = 1e-12, atol: float = 1e-14, max_iterations: int = 20,
                 reuse_rate: float = 0.1):
        if not (rtol >= 4.0 * _EPS and math.isfinite(rtol)):
            raise ValueError(f"rtol = {rtol!r} is invalid: expected a finite value >= {4.0 * _EPS:.3g}")
        if not (atol >= 0.0 and math.isfinite(atol)):
            raise ValueError(f"atol = {atol!r} is invalid: expected a finite value >= 0")
        if int(max_iterations) != max_iterations or max_iterations < 2:
            raise ValueError(f"max_iterations = {max_iterations!r} is invalid: expected an integer >= 2")
        if not (0.0 < reuse_rate < 1.0):
            raise ValueError(f"reuse_rate = {reuse_rate!r} is invalid: expected 0 < reuse_rate < 1")
        self.rtol = float(rtol)
        self.atol = float(atol)
        self.max_iterations = int(max_iterations)
        self.reuse_rate = float(reuse_rate)
        #: Number of Jacobian evaluations since construction or :meth:`reset` (diagnostics).
        self.jacobian_evaluations = 0
        self.reset()

    def __repr__(self) -> str:
        return (f"ImplicitMidpoint(rtol={self.rtol!r}, atol={self.atol!r}, "
                f"max_iterations={self.max_iterations!r}, reuse_rate={self.reuse_rate!r})")

    def reset(self) -> None:
        self._M = None  # (I - h/2 J)^-1
        self._f = None
        self._h = None
        self._k = None  # last converged midpoint slope (predictor)

    def predicted_max_step(self, omega_max: float, damping_ratio: float = 0.0) -> float:
        """``math.inf``: A-stable, every mode with ``Re(lambda) <= 0`` is stable at any step."""
        check_omega_max(omega_max)
        check_damping_ratio(damping_ratio)
        return math.inf

    def stability_function(self, z):
        """``R(z) = (1 + z/2) / (1 - z/2)``."""
        return (1.0 + 0.5 * z) / (1.0 - 0.5 * z)

    def eigenvalue_max_step(self, lam: complex) -> float:
        """``math.inf`` for ``Re(lambda) <= 0`` (A-stable; within ``MARGINAL_REAL_PART |lambda|`` of 0
        counts as 0), else ``0.0`` (it then grows, as the exact flow does)."""
        lam = complex(lam)
        return math.inf if lam.real <= MARGINAL_REAL_PART * abs(lam) else 0.0

    def _jacobian(self, f, t, x, u, fx):
        jac = getattr(f, "jac", None)
        if jac is None:
            jac = getattr(getattr(f, "__self__", None), "jac", None)
        self.jacobian_evaluations += 1
        if jac is not None:
            return np.asarray(jac(t, x, u), dtype=float)
        n = x.shape[0]
        J = np.empty((n, n))
        xp = x.copy()
        for j in range(n):
            xj = x[j]
            d = _SQRT_EPS * max(abs(xj), 1.0)
            xp[j] = xj + d
            d = xp[j] - xj  # exactly representable increment
            J[:, j] = (f(t, xp, u) - fx) / d
            xp[j] = xj
        return J

    def _refresh(self, f, t, x, u, fx, h):
        n = x.shape[0]
        A = np.eye(n)
        A -= (0.5 * h) * self._jacobian(f, t, x, u, fx)
        try:
            self._M = np.linalg.inv(A)
        except np.linalg.LinAlgError:
            self._M = np.linalg.pinv(A)
        self._f = f
        self._h = h

    def step(self, f, t, x, u, h):
        h2 = 0.5 * h
        tm = t + h2
        M = self._M
        if M is None or self._h != h or M.shape[0] != x.shape[0] or not (self._f is f or self._f == f):
            M = None
            k = f(t, x, u)  # cold start: explicit slope as predictor
        else:
            k = self._k.copy()
        fresh = False  # M was evaluated during this step
        tol = self.atol + self.rtol * float(np.abs(x).max())
        previous = math.inf
        rate = 0.0
        total = 0
        while True:
            xm = k * h2
            xm += x
            fm = f(tm, xm, u)
            if M is None:
                self._refresh(f, tm, xm, u, fm, h)
                M = self._M
                fresh = True
                previous = math.inf
            dk = M @ (k - fm)
            k -= dk
            total += 1
            correction = h * float(np.abs(dk).max())
            if correction <= tol or correction <= tol + self.rtol * h * float(np.abs(k).max()):
                break
            if not math.isfinite(correction):
                if fresh:
                    self.reset()
                    raise NewtonConvergenceError(t, correction, total, h)
                k = f(t, x, u)  # the stale matrix threw the iterate away: restart
                M = None
                continue
            rate = correction / previous
            if fresh and rate > 0.5 and correction <= _SQRT_EPS * max(float(np.abs(x).max()),
                                                                       h * float(np.abs(k).max())):
                break  # stagnating at the round-off floor of f: as converged as it can be
            if total >= self.max_iterations:
                self.reset()
                raise NewtonConvergenceError(t, correction, total, h)
            if rate > self.reuse_rate:
                M = None  # slow: re-evaluate the Jacobian at the current iterate
            previous = correction
        if not (total <= 2 or rate <= self.reuse_rate):
            self._M = None  # slow this step: refresh at the start of the next one
        self._k = k
        x_next = k * h
        x_next += x
        return x_next
