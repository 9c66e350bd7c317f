"""Singly diagonally implicit Runge-Kutta schemes solved by simplified Newton: the machinery shared by
implicit midpoint and implicit (backward) Euler, the one-stage theta-methods."""

from __future__ import annotations

import math

import numpy as np

from coopctrl.errors import DivergenceError
from coopctrl.integrators.base import MARGINAL_REAL_PART, check_damping_ratio, check_omega_max
from coopctrl.integrators.stepping import CompiledScheme

_EPS = np.finfo(float).eps


class NewtonConvergenceError(DivergenceError):
    """The Newton iteration of an implicit step did not converge.

    Attributes:
        time: Time [s] at the start of the failed step.
        quantity: ``"Newton correction"``.
        value: Max-norm of the last Newton correction of the state (same units as ``x``).
        suggested_step: Half the step that failed [s].
        iterations: Number of Newton iterations performed.
        step: The step [s] that failed.
        scheme: Registry name of the scheme (``"implicit_midpoint"``).
    """

    def __init__(self, time: float, value: float, iterations: int, step: float, scheme: str = "implicit_midpoint"):
        self.time = time
        self.quantity = "Newton correction"
        self.value = value
        self.suggested_step = 0.5 * step
        self.iterations = iterations
        self.step = step
        self.scheme = scheme
        Exception.__init__(
            self,
            f"{scheme}: Newton did not converge at t = {time:.6g} s with h = {step:.3g} s "
            f"after {iterations} iterations (last correction {value:.3g}); reduce the step "
            f"(try {0.5 * step:.3g} s), raise max_iterations, or check the plant for a "
            "non-finite or discontinuous right-hand side",
        )


class DiagonallyImplicitRungeKutta(CompiledScheme):
    """A singly diagonally implicit Runge-Kutta scheme (SDIRK), each stage solved by simplified Newton.

    With the Butcher tableau ``(A, b, c)``, ``A`` lower triangular with the same diagonal entry
    ``gamma`` on every stage (``c_i = sum_j a_ij``), a step solves the stage slopes ``k_i`` one after
    the other and combines them:

    .. math::

        k_i = f\\!\\left(t_k + c_i h,\\; x_k + h \\sum_{j<i} a_{ij} k_j + \\gamma h k_i,\\; u_k\\right),
        \\qquad x_{k+1} = x_k + h \\sum_i b_i k_i

    One stage with ``a_11 = c_1 = theta``, ``b_1 = 1`` is the one-stage **theta-method**
    ``x_{k+1} = x_k + h f(t_k + theta h, x_k + theta h k)``: ``theta = 1/2`` implicit midpoint,
    ``theta = 1`` backward Euler.

    Each stage equation ``G(k_i) = k_i - f(t + c_i h, S_i + gamma h k_i, u) = 0`` (``S_i`` the known
    part) is solved by **simplified Newton** with the iteration matrix ``M = (I - gamma h J)^-1``,
    ``J = df/dx``: the same matrix for every stage, since ``gamma`` is. ``J`` is by forward finite
    differences (``n`` extra calls of ``f``; increment ``d_j = sqrt(eps) max(|x_j|, 1)``, rounded to a
    representable one), as in the loop's kernel. ``M`` is kept across iterations, stages and steps
    while Newton converges fast (contraction rate at most ``reuse_rate``); it is refreshed at the
    current iterate when convergence slows, and when ``f``, ``h`` or the state size change. Each stage
    starts from its slope of the previous step (the first stage of a cold start from ``f(t, x, u)``,
    a later one from the previous stage). Convergence:
    ``h max|dk| <= atol + rtol max(max|x_k|, h max|k|)``, or the round-off floor of ``f``: with a
    fresh Jacobian the correction stops shrinking (rate above 1/2) while already below
    ``sqrt(eps) max(max|x_k|, h max|k|)`` (a very stiff spring, ``k / m ~ 1e12``, turns the last bits of
    the positions into accelerations that no Newton step can reduce further). Failure raises
    :class:`NewtonConvergenceError` (an :class:`ArithmeticError`).

    Stability: on ``dx/dt = lambda x`` one step multiplies ``x`` by the rational function
    ``R(z) = 1 + z b^T (I - z A)^-1 1`` of ``z = h lambda``, written
    ``R(z) = N(z) / (1 - gamma z)^s`` with the numerator coefficients
    :attr:`stability_numerator` (``s`` stages). The built-in schemes are A-stable
    (``|R(z)| <= 1`` on the closed left half-plane), so :meth:`predicted_max_step` is ``math.inf``.

    The step is the compiled core's (:mod:`coopctrl.integrators.compiled`; the loop's tick runs the same). The
    cached iteration matrix and stage slopes are the only state; :meth:`reset` drops them. Use
    one instance per simulation.

    Args:
        rtol: Relative Newton tolerance [-].
        atol: Absolute Newton tolerance, in the units of ``x``.
        max_iterations: Newton iterations allowed per stage.
        reuse_rate: Largest contraction rate [-] ``|dk_j| / |dk_(j-1)|`` at which ``M`` is kept,
            within the step and for the next one; above it the Jacobian is re-evaluated at the
            current iterate (full Newton in the worst case).

    Subclasses set :attr:`tableau` (the rows of ``A``), :attr:`weights` (``b``) and
    :attr:`stability_numerator`.
    """

    #: Rows of the lower-triangular ``A``; every diagonal entry is ``gamma``.
    tableau: tuple[tuple[float, ...], ...] = ()
    #: ``b``: the weights of the stage slopes in the step.
    weights: tuple[float, ...] = ()
    #: Coefficients ``(n_0, n_1, ...)`` of the numerator ``N(z) = sum_k n_k z^k`` of ``R(z)``.
    stability_numerator: tuple[float, ...] = ()

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
        super().__init__()

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.tableau:
            s = len(cls.tableau)
            gamma = cls.tableau[0][0]
            if (len(cls.weights) != s or any(len(row) != i + 1 for i, row in enumerate(cls.tableau))
                    or any(row[-1] != gamma for row in cls.tableau) or not gamma > 0.0):
                raise TypeError(f"{cls.__name__}: tableau must be lower triangular with one diagonal gamma > 0 "
                                "and as many weights as stages")

    @property
    def gamma(self) -> float:
        """The diagonal entry ``gamma`` of ``A`` [-]."""
        return self.tableau[0][0]

    @property
    def nodes(self) -> tuple[float, ...]:
        """``c_i = sum_j a_ij`` [-]: stage ``i`` is evaluated at ``t + c_i h``."""
        return tuple(math.fsum(row) for row in self.tableau)

    def __repr__(self) -> str:
        return (f"{type(self).__name__}(rtol={self.rtol!r}, atol={self.atol!r}, "
                f"max_iterations={self.max_iterations!r}, reuse_rate={self.reuse_rate!r})")

    @property
    def jacobian_evaluations(self) -> int:
        """Number of Jacobian evaluations since construction or :meth:`reset` (diagnostics)."""
        return self._stepper.jacobian_evaluations()

    # ------------------------------------------------------------------ linear stability
    def predicted_max_step(self, omega_max: float, damping_ratio: float = 0.0) -> float:
        """``math.inf``: A-stable, every mode with ``Re(lambda) <= 0`` is stable at any step."""
        check_omega_max(omega_max)
        check_damping_ratio(damping_ratio)
        return math.inf

    def stability_function(self, z):
        """``R(z) = N(z) / (1 - gamma z)^s`` (:attr:`stability_numerator`, ``s`` stages)."""
        num = np.polynomial.polynomial.polyval(z, self.stability_numerator)
        return num / (1.0 - self.gamma * z) ** len(self.tableau)

    def eigenvalue_max_step(self, lam: complex) -> float:
        """``math.inf`` for ``Re(lambda) <= 0`` (A-stable; within ``MARGINAL_REAL_PART |lambda|`` of 0
        counts as 0), else ``0.0`` (``|R(h lambda)| > 1`` for small ``h``, as the exact flow grows)."""
        lam = complex(lam)
        return math.inf if lam.real <= MARGINAL_REAL_PART * abs(lam) else 0.0
