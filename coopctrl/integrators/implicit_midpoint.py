"""Implicit midpoint rule solved by simplified Newton."""

from __future__ import annotations

from coopctrl.integrators.diagonally_implicit import DiagonallyImplicitRungeKutta, NewtonConvergenceError


class ImplicitMidpoint(DiagonallyImplicitRungeKutta):
    """Implicit midpoint rule, order 2, A-stable and symplectic.

    .. math::

        x_{k+1} = x_k + h\\, f\\!\\left(t_k + \\tfrac h2,\\; \\tfrac{x_k + x_{k+1}}{2},\\; u_k\\right)

    solved for the midpoint slope ``k = (x_{k+1} - x_k) / h`` by **simplified Newton**:
    ``G(k) = k - f(t + h/2, x_k + h k / 2, u) = 0`` with the iteration matrix
    ``M = (I - h/2 J)^-1``, ``J = df/dx`` (the one-stage theta-method with ``theta = 1/2``; the
    Newton machinery, the Jacobian reuse and the tolerances are those of
    :class:`~coopctrl.integrators.diagonally_implicit.DiagonallyImplicitRungeKutta`). Failure raises
    :class:`NewtonConvergenceError` (an :class:`ArithmeticError`).

    Stability: ``R(z) = (1 + z/2) / (1 - z/2)``; ``|R(z)| <= 1`` on the whole closed left
    half-plane (A-stable), ``|R(i y)| = 1`` on the imaginary axis: an undamped oscillator keeps
    its amplitude at any step, so :meth:`predicted_max_step` is ``math.inf``. The scheme is
    symplectic and conserves every quadratic invariant exactly (up to the Newton tolerance),
    e.g. the energy of a linear oscillator. Accuracy still needs ``h`` small against the time
    scales of interest (phase error ``~ (h omega)^2 / 12`` per radian).

    Not L-stable: ``R(z) -> -1`` as ``|z| -> inf``, so a mode far beyond the step
    (``h omega >> 1``) is neither resolved nor damped: it flips sign each step at its full amplitude.
    In a closed loop that samples the contact forces every period, that undamped stiff mode is fed
    back; use :class:`~coopctrl.integrators.implicit_euler.ImplicitEuler` there.

    Args: the Newton options of :class:`~coopctrl.integrators.diagonally_implicit.DiagonallyImplicitRungeKutta`
        (``rtol``, ``atol``, ``max_iterations``, ``reuse_rate``).
    """

    name = "implicit_midpoint"
    order = 2
    tableau = ((0.5,),)
    weights = (1.0,)
    stability_numerator = (1.0, 0.5)


__all__ = ["ImplicitMidpoint", "NewtonConvergenceError"]
