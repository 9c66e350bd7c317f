"""Error-controlled integration of one control period: ``rk23``, ``rk45`` and ``trbdf2``, their plans and codes.

The schemes run in the C++ core (coopctrl/core/adaptive_schemes.h, on the plans made here), in the loop's tick
and behind :meth:`Integrator.step <coopctrl.integrators.Integrator.step>`; this module states them.

The torques are held over the period ``[t, t + T]`` (zero-order hold). Inside it the step ``h`` [s]
is chosen so that each step's local error estimate ``e`` meets the tolerances,

.. math::

    \\|e\\| = \\sqrt{\\frac{1}{n_x} \\sum_c \\left(\\frac{e_c}{atol_c + rtol \\max(|x_c|, |x'_c|)}\\right)^2} \\le 1,

with ``atol_c`` = ``simulation.atol`` [m, rad] on the positions and ``simulation.atol_velocity``
[m/s, rad/s] on the velocities (``x = (z, dz)``). The last step is cut to land exactly on
``t + T`` (with the PI controller, a remainder between one and two steps is taken in two equal
steps rather than a full step and a sliver); the step proposed before that cut carries over to the
next period.

Explicit pairs (:class:`EmbeddedPlan`): Bogacki-Shampine 3(2) (``rk23``) and Dormand-Prince 5(4)
(``rk45``), both first-same-as-last: the slope at a step's end is the next step's first. The step
is advanced with the higher order (local extrapolation), ``e = h sum_j E_j k_j``. The step factor:

- accepted (``|e| < 1``): Gustafsson's PI controller (Hairer and Wanner, *Solving ODEs II*,
  IV.2, eq. 2.43c), ``fac = safety |e_n|^-beta1 |e_(n-1)|^beta2`` with ``beta1 = 0.7 / k``,
  ``beta2 = 0.4 / k``, ``k = q + 1`` (``q`` the order of the error estimate), limited to
  ``[min_factor, max_factor]``, and to 1 right after a rejection;
- rejected: ``fac = max(min_factor, safety |e|^(-1/k))``.

With ``controller = CONTROLLER_ELEMENTARY`` the accepted factor is ``safety |e|^(-1/k)`` (scipy's
``RK23``/``RK45``): the same steps as :func:`scipy.integrate.solve_ivp` on a period, which
``tests/test_integrators_adaptive_plans.py`` checks step for step. ``CONTROLLER_FIXED`` takes every step of
``h = memo[2]`` without control (the order tests).

TR-BDF2 (:class:`TRBDF2Plan`; Hosea and Shampine, *Applied Numerical Mathematics* 20, 1996): the
trapezoidal rule to ``t + gamma h`` and BDF2 to ``t + h`` as a three-stage ESDIRK,
``gamma = 2 - sqrt(2)``, ``d = gamma / 2``, ``w = sqrt(2) / 4``:

.. math::

    k_1 = f(x), \\quad k_2 = f(x + h (d k_1 + d k_2)), \\quad
    k_3 = f(x + h (w k_1 + w k_2 + d k_3)), \\quad x' = x + h (w k_1 + w k_2 + d k_3),

L-stable and stiffly accurate (order 2); the error estimate ``e = M h sum_j (b_j - bh_j) k_j``
with the third-order weights ``bh = ((1 - w) / 3, (3 w + 1) / 3, d / 3)``, filtered by
``M = (I - d h J)^-1`` (Shampine's filter: the stiff components' estimate stays bounded). Each
implicit stage is solved by simplified Newton with ``M``; the Jacobian ``J`` (forward differences, as the
fixed-step implicit schemes of :mod:`coopctrl.integrators.compiled`) is kept from step to step and tick to tick
and re-evaluated only when Newton converges slowly. To keep ``M`` too, the period is cut into ``n`` equal steps
``h = T / n``: ``n`` (and the rest of the period's plan) changes only when the controller's step
leaves ``[h, 1.5 h]``, so a steady run inverts ``I - d h J`` once.

The first step of a run is scipy's ``select_initial_step`` (Hairer, Norsett and Wanner I, II.4):
``h0 = 0.01 |x| / |f0|`` in the tolerance norm (1e-6 s when either is below 1e-5), then
``h1 = (0.01 / max(|f0|, |f1 - f0| / h0))^(1 / (order + 1))`` from one explicit Euler step, and
``min(100 h0, h1, T)``; the next periods start from the step carried over.

A step below ``min_step`` returns :data:`~coopctrl.integrators.compiled.STEP_TOO_SMALL` (its report's ``value = (h, t)``);
the caller names the stiffest mode. Every period's accepted and rejected steps, right-hand-side evaluations and
smallest step are written to the plan's ``stats`` row of the tick ``k = round(t / T)``.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

#: Step controllers (``settings[S_CONTROLLER]``).
CONTROLLER_PI = 0
CONTROLLER_ELEMENTARY = 1
CONTROLLER_FIXED = 2

#: Indices into ``settings`` (float64).
S_RTOL, S_MIN_STEP, S_SAFETY, S_MIN_FACTOR, S_MAX_FACTOR, S_ERROR_ORDER, S_CONTROLLER, S_PERIOD, S_NEWTON_TOL, \
    S_MAX_ITER = range(10)
#: Indices into ``memo`` (float64): the step carried to the next period [s] (0: none yet), the last
#: accepted error norm, the fixed step of ``CONTROLLER_FIXED`` [s], the steps per period of TR-BDF2,
#: ``M``'s step ``d h`` [s] (0: no ``M``), ``J`` is current (1.0/0.0), Jacobian evaluations, ``J`` was
#: evaluated at the state of the step being tried (1.0/0.0).
M_CARRY, M_ERR_PREV, M_FIXED, M_PARTS, M_GH, M_HAVE_J, M_JACOBIANS, M_FRESH = range(8)
#: Columns of ``stats`` (one row per tick): accepted steps, rejected steps, right-hand-side
#: evaluations, smallest accepted step [s].
STAT_ACCEPTED, STAT_REJECTED, STAT_RHS, STAT_MIN_STEP = range(4)

#: The explicit embedded pairs: ``settings``, ``atol`` (nx,); the tableau ``A`` (s, s), ``B`` (s,),
#: ``C`` (s,), ``E`` (s + 1,); ``K`` (s + 1, nx) the slopes; ``y``, ``ynew`` (nx,) work; ``memo``; ``stats``.
EmbeddedPlan = namedtuple("EmbeddedPlan", "settings atol A B C E K y ynew memo stats")
#: TR-BDF2: ``settings``, ``atol``; ``J``, ``Ah``, ``LU``, ``M`` (nx, nx); ``k1 k2 k3 known xs fs dk e y xp fp``
#: (nx,) work; ``memo``; ``stats``.
TRBDF2Plan = namedtuple("TRBDF2Plan", "settings atol J Ah LU M k1 k2 k3 known xs fs dk e y xp fp memo stats")


def step_statistics(ticks: int) -> np.ndarray:
    """A plan's empty ``stats``: a row per tick (at least one) of zero steps and no smallest step (NaN: a tick
    that does not advance, the last of a run, has none)."""
    stats = np.zeros((max(int(ticks), 1), 4))
    stats[:, STAT_MIN_STEP] = np.nan
    return stats


def adaptive_plan(integrator, nx: int, period: float, ticks: int, controller: str | None = None,
                  fixed_step: float = 0.0):
    """A fresh plan of an :class:`~coopctrl.integrators.ErrorControlled` scheme for a run of ``ticks``
    control periods of ``period`` [s] on a state of size ``nx = 2 nz`` (tolerances from
    :meth:`~coopctrl.integrators.ErrorControlled.tolerances`).

    ``controller``: ``"pi"``, ``"elementary"`` or ``"fixed"`` (every step ``fixed_step`` [s], no
    control: the order tests); default the integrator's."""
    from coopctrl.integrators import TRBDF2

    mode = {"pi": CONTROLLER_PI, "elementary": CONTROLLER_ELEMENTARY, "fixed": CONTROLLER_FIXED}[
        controller or integrator.controller]
    settings = np.zeros(10)
    settings[S_RTOL] = integrator.rtol
    settings[S_MIN_STEP] = integrator.min_step
    settings[S_SAFETY] = 0.9
    settings[S_MIN_FACTOR] = 0.2
    settings[S_MAX_FACTOR] = 10.0
    settings[S_ERROR_ORDER] = integrator.error_order
    settings[S_CONTROLLER] = mode
    settings[S_PERIOD] = period
    atol = integrator.tolerances(nx // 2, period)
    memo = np.zeros(8)
    memo[M_FIXED] = fixed_step
    stats = step_statistics(ticks)
    if isinstance(integrator, TRBDF2):
        settings[S_NEWTON_TOL] = integrator.newton_tol
        settings[S_MAX_ITER] = integrator.max_iterations
        return TRBDF2Plan(settings, atol, *(np.zeros((nx, nx)) for _ in range(4)), *(np.zeros(nx) for _ in range(11)),
                          memo, stats)
    s = len(integrator.B)
    A = np.array(integrator.A, dtype=float)
    return EmbeddedPlan(settings, atol, A, np.array(integrator.B, dtype=float), np.array(integrator.C, dtype=float),
                        np.array(integrator.E, dtype=float), np.zeros((s + 1, nx)), np.zeros(nx), np.zeros(nx), memo,
                        stats)
