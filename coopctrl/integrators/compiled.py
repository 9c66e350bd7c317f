"""The fixed-step integrators' plans and codes: what the compiled core's schemes read and report.

The schemes run in the C++ core (coopctrl/core: explicit_schemes.h, implicit_schemes.h, integration_plan.h),
in the loop's tick and behind :meth:`Integrator.step <coopctrl.integrators.Integrator.step>` of the five
built-in schemes. One control period is integrated with the torques held (zero-order hold), one step of the
chosen scheme per entry ``h_s`` [s] of ``steps`` (``T / substeps`` each, or the free step of
:meth:`ClosedLoop.set_step <coopctrl.closed_loop.ClosedLoop.set_step>`: ``floor(T / h)`` steps and a
remainder). The classes of :mod:`coopctrl.integrators` are its configuration, :func:`make_plan` its plan:

- an :class:`ExplicitPlan` for ``"euler"``, ``"symplectic_euler"`` and ``"rk4"`` (the scheme is a run-time
  code, :mod:`coopctrl.integrators.methods`), one step from ``t`` [s]:

  - euler: ``x' = x + h f(t, x)``;
  - symplectic_euler: ``dz' = dz + h ddz(t, x)``, then ``z' = z + h dz'``;
  - rk4: ``k1 = f(t, x)``, ``k2 = f(t + h/2, x + h/2 k1)``, ``k3 = f(t + h/2, x + h/2 k2)``,
    ``k4 = f(t + h, x + h k3)``, ``x' = x + h/6 ((k2 + k3) 2 + k1 + k4)``;

  the first step of a period takes its first slope from the control terms the tick sensed (the same bits);
- an :class:`ImplicitPlan` for ``"implicit_midpoint"`` and ``"implicit_euler"``: the singly diagonally
  implicit Runge-Kutta step of
  :class:`~coopctrl.integrators.diagonally_implicit.DiagonallyImplicitRungeKutta` (its tableau in the
  plan), each stage ``G(k_i) = k_i - f(S_i + gamma h k_i) = 0`` solved by simplified Newton with
  ``M = (I - gamma h J)^-1`` (its pseudo-inverse where that matrix is singular): the forward-difference
  Jacobian (column ``j`` is ``(f(x + d_j e_j) - f(x)) / d_j``, ``d_j = sqrt(eps) max(|x_j|, 1)`` rounded to a
  representable increment), predictors, convergence test, round-off stop, Jacobian reuse (``reuse_rate``) and
  failure (:data:`STEP_NEWTON_FAILED`, which :func:`newton_failure` turns into
  :class:`~coopctrl.integrators.NewtonConvergenceError`). ``M`` and the stage slopes are kept from step to
  step, tick to tick; a new plan starts cold.

The error-controlled schemes' plans are :mod:`coopctrl.integrators.adaptive_plans`'. Every work array is in the
plan, made once per run by :func:`make_plan`: a step allocates nothing. ``tests/_integrator_oracle.py`` keeps
the schemes' arithmetic in numpy as an independent check, itself checked against
:func:`scipy.integrate.solve_ivp`.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from coopctrl.integrators.methods import (METHOD_ADAPTIVE, METHOD_EULER, METHOD_RK4, METHOD_SDIRK,  # noqa: F401 (API)
                                          METHOD_SYMPLECTIC_EULER)

#: Results of a period's integration. Its report (a :class:`coopctrl._core.StopReport`): ``rhs_evaluations`` counts
#: the right-hand-side evaluations; on :data:`STEP_NEWTON_FAILED` ``detail[0]`` is the index of the failed step in
#: ``steps``, ``detail[1]`` the Newton iterations of the failed stage and ``value = (last Newton correction, time [s]
#: at the start of the failed step)``.
STEP_OK = 0  #: the period is integrated
STEP_PLANT_ERROR = 1  #: the right-hand side failed (``status`` holds its code, ``x_fail`` the state it was called at)
STEP_TOO_SMALL = 3  #: an error-controlled step fell below ``min_step`` (:mod:`coopctrl.integrators.adaptive_plans`; ``value = (step [s], time [s])``)
STEP_NEWTON_FAILED = 2  #: an implicit stage did not converge (``detail[:2]``, ``value``)

#: Work arrays of the explicit schemes (float64 ``(nx,)`` each): the slopes ``k1 .. k4`` and the stage state ``y``.
ExplicitPlan = namedtuple("ExplicitPlan", "method k1 k2 k3 k4 y")

#: The diagonally implicit scheme and its Newton state (see :func:`make_plan`):
#: ``settings`` = ``(rtol [-], atol [units of x], max_iterations, reuse_rate [-])``; ``tableau`` ``(s, s)``
#: (lower triangular, diagonal ``gamma``), ``weights`` ``(s,)`` = ``b``, ``nodes`` ``(s,)`` = ``c``;
#: ``M`` ``(nx, nx)`` the iteration matrix ``(I - gamma h J)^-1``, ``A`` and ``LU`` ``(nx, nx)`` work;
#: ``slopes`` and ``predictors`` ``(s, nx)``; ``known``, ``k``, ``xs``, ``fs``, ``dk``, ``xp``, ``fp``
#: ``(nx,)`` work; ``memo`` float64 ``(3,)`` = (``M`` is kept: 1.0 / 0.0, the step ``h`` [s] it was made
#: for, Jacobian evaluations so far: ``jacobian_evaluations`` of the scheme object).
ImplicitPlan = namedtuple("ImplicitPlan", "settings tableau weights nodes M A LU slopes predictors "
                                          "known k xs fs dk xp fp memo")


def make_plan(integrator, nx: int, period: float | None = None, ticks: int = 1):
    """A fresh plan (work arrays, cold Newton state) for one run of ``integrator`` on a state of size ``nx``.

    Args:
        integrator: An :class:`~coopctrl.integrators.ExplicitEuler`,
            :class:`~coopctrl.integrators.SymplecticEuler`, :class:`~coopctrl.integrators.RungeKutta4`,
            a :class:`~coopctrl.integrators.DiagonallyImplicitRungeKutta` (implicit midpoint,
            implicit Euler; its Newton settings are read now) or an
            :class:`~coopctrl.integrators.ErrorControlled` scheme (:mod:`coopctrl.integrators.adaptive_plans`).
        nx: State size ``2 nz``.
        period: The control period ``T`` [s] (the error-controlled schemes integrate ``[t, t + T]``).
        ticks: Ticks of the run (the error-controlled schemes' step statistics have a row each).

    Raises:
        TypeError: for another integrator.
    """
    from coopctrl.integrators import (DiagonallyImplicitRungeKutta, ErrorControlled, ExplicitEuler, RungeKutta4,
                                      SymplecticEuler)

    if isinstance(integrator, ErrorControlled):
        import coopctrl.integrators.adaptive_plans as adaptive_plans

        if period is None:
            raise TypeError("make_plan: an error-controlled scheme needs the control period [s]")
        return adaptive_plans.adaptive_plan(integrator, nx, period, ticks)

    explicit = {ExplicitEuler: METHOD_EULER, SymplecticEuler: METHOD_SYMPLECTIC_EULER, RungeKutta4: METHOD_RK4}
    for cls, method in explicit.items():
        if isinstance(integrator, cls):
            return ExplicitPlan(np.int64(method), *(np.zeros(nx) for _ in range(5)))
    if not isinstance(integrator, DiagonallyImplicitRungeKutta) or not integrator.tableau:
        raise TypeError(f"integrator {type(integrator).__name__!r} has no compiled step")
    s = len(integrator.tableau)
    tableau = np.zeros((s, s))
    for i, row in enumerate(integrator.tableau):
        tableau[i, :len(row)] = row
    settings = np.array([integrator.rtol, integrator.atol, float(integrator.max_iterations), integrator.reuse_rate])
    return ImplicitPlan(settings, tableau, np.array(integrator.weights, dtype=float),
                        np.array(integrator.nodes, dtype=float), np.zeros((nx, nx)), np.zeros((nx, nx)),
                        np.zeros((nx, nx)), np.zeros((s, nx)), np.zeros((s, nx)),
                        *(np.zeros(nx) for _ in range(7)), np.zeros(3))


def newton_failure(scheme: str, steps, report):
    """The :class:`~coopctrl.integrators.NewtonConvergenceError` of a period that returned
    :data:`STEP_NEWTON_FAILED` on the period ``steps``, from its ``report`` (a :class:`coopctrl._core.StopReport`:
    ``detail = (failed step, iterations, -)``, ``value = (last correction, time [s])``)."""
    from coopctrl.integrators import NewtonConvergenceError

    failed_step, iterations, _ = report.detail
    correction, time = report.value
    return NewtonConvergenceError(float(time), float(correction), int(iterations), float(steps[failed_step]), scheme)
