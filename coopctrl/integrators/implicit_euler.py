"""Implicit (backward) Euler solved by simplified Newton: the L-stable scheme for stiff interconnections."""

from __future__ import annotations

from coopctrl.integrators.diagonally_implicit import DiagonallyImplicitRungeKutta


class ImplicitEuler(DiagonallyImplicitRungeKutta):
    """Implicit (backward) Euler, order 1, L-stable and stiffly accurate.

    .. math::

        x_{k+1} = x_k + h\\, f\\!\\left(t_k + h,\\; x_{k+1},\\; u_k\\right)

    solved for the end slope ``k = (x_{k+1} - x_k) / h`` by **simplified Newton**:
    ``G(k) = k - f(t + h, x_k + h k, u) = 0`` with the iteration matrix ``M = (I - h J)^-1``,
    ``J = df/dx`` (the one-stage theta-method with ``theta = 1``; the Newton machinery, the Jacobian
    reuse and the tolerances are those of
    :class:`~coopctrl.integrators.diagonally_implicit.DiagonallyImplicitRungeKutta`). Failure raises
    :class:`~coopctrl.integrators.diagonally_implicit.NewtonConvergenceError`.

    Stability: ``R(z) = 1 / (1 - z)``. ``|R(z)| <= 1`` on the closed left half-plane (A-stable,
    :meth:`predicted_max_step` is ``math.inf``) and ``R(z) -> 0`` as ``|z| -> inf`` (**L-stable**);
    the new state is the last (only) stage, the equation solved at ``t + h`` (stiffly accurate). On an
    undamped mode ``z = i h omega``:

    .. math:: |R(i h \\omega)| = \\frac{1}{\\sqrt{1 + (h \\omega)^2}}

    so a stiff mode far beyond the step (``h omega >> 1``) is damped by ``~ 1 / (h omega)`` in a
    single step (a grasp spring at ``h omega = 33`` keeps 3 % of its amplitude after one step), and
    its state falls onto the quasi-static equilibrium of the slow motion instead of oscillating about
    it. This is what a closed loop needs when the controller samples the contact forces every period:
    the forces then follow the slow motion, where :class:`~coopctrl.integrators.ImplicitMidpoint`
    (``|R| = 1`` on the imaginary axis, ``R(inf) = -1``) keeps the stiff mode undamped and lets the
    controller feed it.

    The price is that the slow, resolved modes are damped too: ``|R(i y)| = 1 - y^2 / 2 + O(y^4)``
    with ``y = h omega``, an amplitude loss of ``~ (h omega)^2 / 2`` per step, i.e. a numerical
    damping ratio ``~ h omega / 2`` (energy is not conserved; an undamped oscillator decays), and a
    phase error ``~ (h omega)^2 / 3`` per radian (``arg R(i y) = arctan y``). Errors are first order
    in ``h``, so at a given step backward Euler is less accurate than implicit midpoint on anything
    the step resolves. A physically unstable mode (``Re(lambda) > 0``) grows at a small step but is
    damped, wrongly, once ``h |lambda|^2 > 2 Re(lambda)`` (``|1 - z| > 1``): check a result that
    looks stable at a large step against a smaller one.

    Pick it over implicit midpoint for stiff interconnections in closed loop, at steps far beyond
    the explicit stability limits (``h omega_max >> 1``), when the fast modes are not of interest;
    pick implicit midpoint (or RK4) when the step resolves the fastest mode, or when energy must be
    conserved (passive, undamped checks). Measured on ``stiff_grasp_extreme`` with 5e7 N/m grasps at
    ``h = T = 3 ms`` (``h omega_max = 33``, 11.8 times RK4's limit; ``coopctrl tradeoff``): contact-force
    error 0.48 N of 22.5 N, against 134 N for implicit midpoint. A second-order L-stable scheme, the
    two-stage SDIRK with ``gamma = 1 - 1/sqrt(2)`` (``R(z) = (1 + (1 - 2 gamma) z) / (1 - gamma z)^2``),
    tracked the position 17 times better there but the forces 18 times worse (8.5 N: ``|R(33 i)| = 0.14``
    against backward Euler's 0.030) with twice the right-hand-side calls, so it is not offered.

    Args: the Newton options of :class:`~coopctrl.integrators.diagonally_implicit.DiagonallyImplicitRungeKutta`
        (``rtol``, ``atol``, ``max_iterations``, ``reuse_rate``).
    """

    name = "implicit_euler"
    order = 1
    tableau = ((1.0,),)
    weights = (1.0,)
    stability_numerator = (1.0,)
