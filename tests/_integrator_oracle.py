"""The fixed-step schemes in plain numpy: an independent oracle for :mod:`coopctrl.integrators.compiled`.

The package writes each scheme once (:mod:`coopctrl.integrators.compiled`, run compiled in the loop and
by ``Integrator.step``). This file keeps the former Python integrators' arithmetic, vectorized with
numpy and written separately, to check that source against: step for step on the plant
(``tests/test_integrators_compiled.py``), while ``tests/test_integrator_oracle.py`` checks the oracle
itself against scipy's ``solve_ivp`` and the analytic solution of a linear oscillator. Not imported by
the package.

Each step function has the signature ``step(f, t, x, u, h) -> x_next`` (a new array; ``x`` unchanged).
"""

from __future__ import annotations

import math

import numpy as np

from coopctrl.integrators import NewtonConvergenceError

_SQRT_EPS = math.sqrt(np.finfo(float).eps)


def euler_step(f, t, x, u, h):
    """``x + h f(t, x, u)``."""
    dx = f(t, x, u)
    dx *= h
    dx += x
    return dx


def symplectic_euler_step(f, t, x, u, h):
    """``dz' = dz + h ddz(t, x, u)``, then ``z' = z + h dz'``."""
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


def rk4_step(f, t, x, u, h):
    """The classic Runge-Kutta step, its operations in the kernel's order."""
    h2 = 0.5 * h
    t2 = t + h2
    k1 = f(t, x, u)
    y = k1 * h2
    y += x
    k2 = f(t2, y, u)
    y = k2 * h2
    y += x
    k3 = f(t2, y, u)
    y = k3 * h
    y += x
    k4 = f(t + h, y, u)
    k2 += k3
    k2 *= 2.0
    k2 += k1
    k2 += k4
    k2 *= h / 6.0
    k2 += x
    return k2


EXPLICIT = {"euler": euler_step, "symplectic_euler": symplectic_euler_step, "rk4": rk4_step}


class SDIRK:
    """A singly diagonally implicit Runge-Kutta step by simplified Newton, with numpy's LAPACK inverse and
    BLAS products: the scheme of ``coopctrl.integrators.DiagonallyImplicitRungeKutta`` (its docstring
    states the iteration, the Jacobian reuse and the stopping tests), kept between steps as it keeps them.

    Args:
        scheme: A ``DiagonallyImplicitRungeKutta`` whose tableau, weights and Newton settings are used.
    """

    def __init__(self, scheme):
        self.name = scheme.name
        self.tableau, self.weights = scheme.tableau, scheme.weights
        self.gamma = scheme.tableau[0][0]
        self.nodes = tuple(math.fsum(row) for row in scheme.tableau)
        self.rtol, self.atol = scheme.rtol, scheme.atol
        self.max_iterations, self.reuse_rate = scheme.max_iterations, scheme.reuse_rate
        self.jacobian_evaluations = 0
        self.reset()

    def reset(self):
        self._M = self._f = self._h = self._k = None

    def _jacobian(self, f, t, x, u, fx):
        self.jacobian_evaluations += 1
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
        A = np.eye(x.shape[0]) - (self.gamma * h) * self._jacobian(f, t, x, u, fx)
        try:
            self._M = np.linalg.inv(A)
        except np.linalg.LinAlgError:
            self._M = np.linalg.pinv(A)
        self._f, self._h = f, h

    def step(self, f, t, x, u, h):
        M = self._M
        if M is None or self._h != h or M.shape[0] != x.shape[0] or not (self._f is f or self._f == f):
            M, predictors = None, None  # cold start
        else:
            predictors = self._k
        gh = self.gamma * h
        fresh = slow = False
        tol = self.atol + self.rtol * float(np.abs(x).max())
        slopes = []
        for i, (row, c) in enumerate(zip(self.tableau, self.nodes)):
            ts = t + c * h
            known = x.copy()
            for a, kj in zip(row[:-1], slopes):
                if a != 0.0:
                    known += (a * h) * kj
            if predictors is not None:
                k = predictors[i].copy()
            else:
                k = f(t, x, u) if i == 0 else slopes[-1].copy()
            previous, rate, total = math.inf, 0.0, 0
            while True:
                xs = k * gh
                xs += known
                fs = f(ts, xs, u)
                if M is None:
                    self._refresh(f, ts, xs, u, fs, h)
                    M, fresh, previous = self._M, True, math.inf
                dk = M @ (k - fs)
                k -= dk
                total += 1
                correction = h * float(np.abs(dk).max())
                if correction <= tol or correction <= tol + self.rtol * h * float(np.abs(k).max()):
                    break
                if not math.isfinite(correction):
                    if fresh:
                        self.reset()
                        raise NewtonConvergenceError(t, correction, total, h, self.name)
                    k, M = f(t, x, u), None
                    continue
                rate = correction / previous
                if fresh and rate > 0.5 and correction <= _SQRT_EPS * max(float(np.abs(x).max()),
                                                                           h * float(np.abs(k).max())):
                    break
                if total >= self.max_iterations:
                    self.reset()
                    raise NewtonConvergenceError(t, correction, total, h, self.name)
                if rate > self.reuse_rate:
                    M = None
                previous = correction
            slow = slow or not (total <= 2 or rate <= self.reuse_rate)
            slopes.append(k)
        if slow:
            self._M = None
        self._k = slopes
        x_next = x.copy()
        for b, k in zip(self.weights, slopes):
            x_next += (b * h) * k
        return x_next


def oracle_step(scheme):
    """The oracle's ``step(f, t, x, u, h)`` for a package scheme object (registry name or tableau)."""
    if scheme.name in EXPLICIT:
        return EXPLICIT[scheme.name]
    return SDIRK(scheme).step
