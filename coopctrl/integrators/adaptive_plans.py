"""Error-controlled integration of one control period, compiled: ``rk23``, ``rk45`` and ``trbdf2``.

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
implicit stage is solved by simplified Newton with ``M``; the Jacobian ``J`` (forward differences,
as :mod:`coopctrl.integrators.compiled`) is kept from step to step and tick to tick and re-evaluated only
when Newton converges slowly. To keep ``M`` too, the period is cut into ``n`` equal steps
``h = T / n``: ``n`` (and the rest of the period's plan) changes only when the controller's step
leaves ``[h, 1.5 h]``, so a steady run inverts ``I - d h J`` once.

A step below ``min_step`` returns :data:`STEP_TOO_SMALL` (``out_float = (h, t)``); the caller names
the stiffest mode. Every period's accepted and rejected steps, right-hand-side evaluations and
smallest step are written to the plan's ``stats`` row of the tick ``k = round(t / T)``.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit
from numba.extending import register_jitable

from coopctrl.integrators.compiled import (STEP_OK, STEP_PLANT_ERROR, STEP_TOO_SMALL, copy_into, first_rhs_into, stage_failed,
                                           invert_into, jacobian_into, rhs_into, _pinv_into)

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



@register_jitable
def embedded_plan_of(slots):
    """The :class:`EmbeddedPlan` held in ``slots`` (:func:`coopctrl.integrators.compiled.plan_slots`)."""
    v, mat = slots.vectors, slots.matrices
    return EmbeddedPlan(v[0], v[1], mat[0], v[2], v[3], v[4], mat[1], v[5], v[6], v[7], mat[2])


@register_jitable
def trbdf2_plan_of(slots):
    """The :class:`TRBDF2Plan` held in ``slots`` (:func:`coopctrl.integrators.compiled.plan_slots`)."""
    v, mat = slots.vectors, slots.matrices
    return TRBDF2Plan(v[0], v[1], mat[0], mat[1], mat[2], mat[3], v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9],
                      v[10], v[11], v[12], v[13], mat[4])

_GAMMA = 2.0 - math.sqrt(2.0)
_D = _GAMMA / 2.0
_W = math.sqrt(2.0) / 4.0
#: ``b - bh`` of TR-BDF2 (``b = (w, w, d)``, ``bh = ((1 - w) / 3, (3 w + 1) / 3, d / 3)``).
_E1 = _W - (1.0 - _W) / 3.0
_E2 = _W - (3.0 * _W + 1.0) / 3.0
_E3 = _D - _D / 3.0


@njit(cache=True)
def _rms_scaled(e, x, xn, atol, rtol):
    """``sqrt(mean((e_c / (atol_c + rtol max(|x_c|, |xn_c|)))^2))``; NaN if any term is."""
    acc = 0.0
    n = e.shape[0]
    for c in range(n):
        sc = atol[c] + rtol * max(abs(x[c]), abs(xn[c]))
        v = e[c] / sc
        acc += v * v
    return math.sqrt(acc / n)


@njit(cache=True)
def _tick_of(t, period, stats):
    k = int(t / period + 0.5)
    return k if 0 <= k < stats.shape[0] else -1


@njit(cache=True)
def _record(stats, k, accepted, rejected, evals, hmin):
    if k >= 0:
        stats[k, STAT_ACCEPTED] = accepted
        stats[k, STAT_REJECTED] = rejected
        stats[k, STAT_RHS] = evals
        stats[k, STAT_MIN_STEP] = hmin


@njit(cache=True)
def initial_step(x, f0, y1, f1, atol, rtol, order, interval, tau, P, status, ws):
    """The first step [s] of a run (scipy's ``select_initial_step``, Hairer, Norsett and Wanner I,
    II.4): ``h0 = 0.01 |x| / |f0|`` in the tolerance norm (1e-6 s when either is below 1e-5), then
    ``h1 = (0.01 / max(|f0|, |f1 - f0| / h0))^(1 / (order + 1))`` from one explicit Euler step;
    ``min(100 h0, h1, interval)``. Returns ``-1.0`` on a right-hand-side failure (``y1`` holds the state)."""
    n = x.shape[0]
    d0 = 0.0
    d1 = 0.0
    for c in range(n):
        sc = atol[c] + abs(x[c]) * rtol
        d0 += (x[c] / sc) ** 2
        d1 += (f0[c] / sc) ** 2
    d0 = math.sqrt(d0 / n)
    d1 = math.sqrt(d1 / n)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    h0 = min(h0, interval)
    for c in range(n):
        y1[c] = x[c] + h0 * f0[c]
    rhs_into(y1, tau, P, status, ws, f1)
    if status[0] != 0:
        return -1.0
    d2 = 0.0
    for c in range(n):
        sc = atol[c] + abs(x[c]) * rtol
        d2 += ((f1[c] - f0[c]) / sc) ** 2
    d2 = math.sqrt(d2 / n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / (order + 1.0))
    return min(100.0 * h0, h1, interval)


# ---------------------------------------------------------------------------------------------- explicit pairs
@njit(cache=True)
def embedded_advance(plan, x, tau, P, status, ws, terms, t, x_fail, out_int, out_float):
    """The explicit pair over one control period ``[t, t + T]`` (``T = settings[S_PERIOD]``), ``x``
    in place. Returns :data:`STEP_OK`, :data:`STEP_PLANT_ERROR` (``x_fail`` set) or
    :data:`STEP_TOO_SMALL` (``out_float = (step, time)``)."""
    st = plan.settings
    A, B, C, E, K, y, ynew, memo, atol = plan.A, plan.B, plan.C, plan.E, plan.K, plan.y, plan.ynew, plan.memo, plan.atol
    rtol, min_step, safety = st[S_RTOL], st[S_MIN_STEP], st[S_SAFETY]
    min_factor, max_factor = st[S_MIN_FACTOR], st[S_MAX_FACTOR]
    controller = int(st[S_CONTROLLER])
    period = st[S_PERIOD]
    kexp = st[S_ERROR_ORDER] + 1.0
    beta1 = 0.7 / kexp
    beta2 = 0.4 / kexp
    n = x.shape[0]
    s = B.shape[0]
    t_end = t + period
    k_tick = _tick_of(t, period, plan.stats)
    evals0 = out_int[7]
    accepted = 0
    rejected = 0
    hmin = math.inf
    first_rhs_into(x, tau, P, status, ws, terms, K[0])  # the torque changed at t: a fresh first slope
    if stage_failed(x, status, x_fail, out_int):
        return STEP_PLANT_ERROR
    if controller == CONTROLLER_FIXED:
        h_abs = memo[M_FIXED]
    elif memo[M_CARRY] > 0.0:
        h_abs = memo[M_CARRY]
    else:
        h_abs = initial_step(x, K[0], y, K[s], atol, rtol, st[S_ERROR_ORDER], period, tau, P, status, ws)
        out_int[7] += 1
        if h_abs < 0.0:
            copy_into(x_fail, y)
            return STEP_PLANT_ERROR
    t_cur = t
    while t_cur < t_end:
        step_rejected = False
        while True:
            if h_abs < min_step and controller != CONTROLLER_FIXED:
                out_float[0] = h_abs
                out_float[1] = t_cur
                copy_into(x_fail, x)
                _record(plan.stats, k_tick, accepted, rejected, out_int[7] - evals0, hmin)
                return STEP_TOO_SMALL
            proposal = h_abs
            if controller == CONTROLLER_PI and h_abs < t_end - t_cur < 2.0 * h_abs:
                h_abs = 0.5 * (t_end - t_cur)  # two even steps to the instant, not a sliver after a full one
            t_new = t_cur + h_abs
            clipped = t_new - t_end > 0.0 or h_abs < proposal
            if t_new - t_end > 0.0:
                t_new = t_end
            h = t_new - t_cur
            for i in range(1, s):
                for c in range(n):
                    acc = 0.0
                    for j in range(i):
                        acc += K[j, c] * A[i, j]
                    y[c] = acc * h + x[c]
                rhs_into(y, tau, P, status, ws, K[i])
                if stage_failed(y, status, x_fail, out_int):
                    return STEP_PLANT_ERROR
            for c in range(n):
                acc = 0.0
                for j in range(s):
                    acc += K[j, c] * B[j]
                ynew[c] = x[c] + h * acc
            rhs_into(ynew, tau, P, status, ws, K[s])
            if stage_failed(ynew, status, x_fail, out_int):
                return STEP_PLANT_ERROR
            if controller == CONTROLLER_FIXED:
                err = 0.0
            else:
                acc2 = 0.0
                for c in range(n):
                    e = 0.0
                    for j in range(s + 1):
                        e += K[j, c] * E[j]
                    e *= h
                    sc = atol[c] + max(abs(x[c]), abs(ynew[c])) * rtol
                    v = e / sc
                    acc2 += v * v
                err = math.sqrt(acc2 / n)
            if err < 1.0:
                if controller == CONTROLLER_FIXED:
                    factor = 1.0
                elif err == 0.0:
                    factor = max_factor
                elif controller == CONTROLLER_PI and memo[M_ERR_PREV] > 0.0:
                    factor = safety * err ** (-beta1) * memo[M_ERR_PREV] ** beta2
                    factor = min(max_factor, max(min_factor, factor))
                else:
                    factor = min(max_factor, safety * err ** (-1.0 / kexp))
                if step_rejected:
                    factor = min(1.0, factor)
                h_abs = h * factor
                if controller != CONTROLLER_FIXED:
                    memo[M_ERR_PREV] = max(err, 1e-4)
                if clipped and proposal > h_abs:
                    h_abs = proposal  # the landing cut the step, not the error: carry the step the error allowed
                break
            # rejected (a NaN error too: the step went where the plant is not defined)
            if err == err:
                h_abs = h * max(min_factor, safety * err ** (-1.0 / kexp))
            else:
                h_abs = h * min_factor
            rejected += 1
            step_rejected = True
        for c in range(n):
            x[c] = ynew[c]
            K[0, c] = K[s, c]
        t_cur = t_new
        accepted += 1
        if h < hmin:
            hmin = h
    if controller == CONTROLLER_FIXED:
        h_abs = memo[M_FIXED]
    memo[M_CARRY] = h_abs
    _record(plan.stats, k_tick, accepted, rejected, out_int[7] - evals0, hmin)
    return STEP_OK


# ---------------------------------------------------------------------------------------------- TR-BDF2
@njit(cache=True)
def _jacobian(plan, x, tau, P, status, ws, fx, out_int, x_fail):
    """``plan.J = df/dx`` at ``x`` (``fx = f(x)``) by forward differences (increments as
    :mod:`coopctrl.integrators.compiled`). False on a right-hand-side failure (``x_fail`` set)."""
    plan.memo[M_JACOBIANS] += 1.0
    if not jacobian_into(plan.J, x, tau, P, status, ws, fx, plan.xp, plan.fp, out_int, x_fail):
        return False
    plan.memo[M_HAVE_J] = 1.0
    plan.memo[M_FRESH] = 1.0
    plan.memo[M_GH] = 0.0  # M is for the old J
    return True


@njit(cache=True)
def _iteration_matrix(plan, gh):
    """``plan.M = (I - gh J)^-1``."""
    J, Ah = plan.J, plan.Ah
    n = J.shape[0]
    for r in range(n):
        for c in range(n):
            Ah[r, c] = (1.0 if r == c else 0.0) - gh * J[r, c]
    if not invert_into(Ah, plan.LU, plan.M):
        _pinv_into(Ah, plan.M)
    plan.memo[M_GH] = gh


@njit(cache=True)
def _stage(plan, known, k, tau, P, status, ws, gh, h, x, out_int, x_fail):
    """Solve ``k = f(known + gh k)`` by simplified Newton with ``plan.M`` from the predictor in ``k``.
    Returns 0 (converged), 1 (did not converge: slow or diverging), 2 (right-hand-side failure)."""
    st = plan.settings
    xs, fs, dk, M, atol = plan.xs, plan.fs, plan.dk, plan.M, plan.atol
    rtol, tol = st[S_RTOL], st[S_NEWTON_TOL]
    max_iter = int(st[S_MAX_ITER])
    n = k.shape[0]
    previous = math.inf
    for it in range(max_iter):
        for c in range(n):
            xs[c] = k[c] * gh + known[c]
        rhs_into(xs, tau, P, status, ws, fs)
        if stage_failed(xs, status, x_fail, out_int):
            return 2
        for r in range(n):
            acc = 0.0
            for c in range(n):
                acc += M[r, c] * (k[c] - fs[c])
            dk[r] = acc
        acc2 = 0.0
        for c in range(n):
            k[c] -= dk[c]
            sc = atol[c] + rtol * abs(x[c])
            v = h * dk[c] / sc
            acc2 += v * v
        size = math.sqrt(acc2 / n)
        if not size == size or size == math.inf:
            return 1
        if size <= tol:
            return 0
        rate = size / previous
        if it >= 1 and rate > 0.9:
            return 1
        if it >= 1 and rate < 1.0 and rate / (1.0 - rate) * size <= tol:
            return 0
        previous = size
    return 1


@njit(cache=True)
def trbdf2_advance(plan, x, tau, P, status, ws, terms, t, x_fail, out_int, out_float):
    """TR-BDF2 over one control period ``[t, t + T]``, ``x`` in place (see the module). Returns
    :data:`STEP_OK`, :data:`STEP_PLANT_ERROR` or :data:`STEP_TOO_SMALL`."""
    st = plan.settings
    memo, atol = plan.memo, plan.atol
    k1, k2, k3, known, e, y, dk = plan.k1, plan.k2, plan.k3, plan.known, plan.e, plan.y, plan.dk
    rtol, min_step, safety = st[S_RTOL], st[S_MIN_STEP], st[S_SAFETY]
    min_factor, max_factor = st[S_MIN_FACTOR], st[S_MAX_FACTOR]
    controller = int(st[S_CONTROLLER])
    period = st[S_PERIOD]
    n = x.shape[0]
    k_tick = _tick_of(t, period, plan.stats)
    evals0 = out_int[7]
    accepted = 0
    rejected = 0
    hmin = math.inf
    first_rhs_into(x, tau, P, status, ws, terms, k1)
    if stage_failed(x, status, x_fail, out_int):
        return STEP_PLANT_ERROR
    # steps of this period: T / parts, parts kept while the proposed step stays in [T / parts, 1.5 T / parts]
    if controller == CONTROLLER_FIXED:
        parts = max(1, int(round(period / memo[M_FIXED])))
    else:
        proposal = memo[M_CARRY]
        if proposal <= 0.0:
            proposal = initial_step(x, k1, y, k2, atol, rtol, 2.0, period, tau, P, status, ws)
            out_int[7] += 1
            if proposal < 0.0:
                copy_into(x_fail, y)
                return STEP_PLANT_ERROR
        parts = int(memo[M_PARTS])
        if parts < 1 or proposal < period / parts or proposal > 1.5 * period / parts:
            parts = max(1, int(math.ceil(period / proposal)))
    done = 0.0  # the part of the period integrated [s]
    remaining_parts = parts
    h = period / parts
    while remaining_parts > 0:
        if h < min_step:
            out_float[0] = h
            out_float[1] = t + done
            copy_into(x_fail, x)
            _record(plan.stats, k_tick, accepted, rejected, out_int[7] - evals0, hmin)
            return STEP_TOO_SMALL
        if memo[M_HAVE_J] == 0.0:
            if not _jacobian(plan, x, tau, P, status, ws, k1, out_int, x_fail):
                return STEP_PLANT_ERROR
        gh = _D * h
        if memo[M_GH] != gh:
            _iteration_matrix(plan, gh)
        # stage 2: the trapezoidal rule to t + gamma h
        for c in range(n):
            known[c] = x[c] + gh * k1[c]
            k2[c] = k1[c]
        code = _stage(plan, known, k2, tau, P, status, ws, gh, h, x, out_int, x_fail)
        if code == 0:
            # stage 3: BDF2 to t + h
            for c in range(n):
                known[c] = x[c] + (_W * h) * (k1[c] + k2[c])
                k3[c] = k2[c]
            code = _stage(plan, known, k3, tau, P, status, ws, gh, h, x, out_int, x_fail)
        if code == 2:
            return STEP_PLANT_ERROR
        if code == 1:  # Newton did not converge: a Jacobian at x first, then a smaller step
            rejected += 1
            if memo[M_FRESH] == 0.0:
                memo[M_HAVE_J] = 0.0
            else:
                remaining_parts *= 4
                h = (period - done) / remaining_parts
            continue
        for c in range(n):
            y[c] = known[c] + gh * k3[c]  # x' = x + h (w k1 + w k2 + d k3)
            e[c] = h * (_E1 * k1[c] + _E2 * k2[c] + _E3 * k3[c])
        # Shampine's filter: M e
        M = plan.M
        for r in range(n):
            acc = 0.0
            for c in range(n):
                acc += M[r, c] * e[c]
            dk[r] = acc
        err = 0.0 if controller == CONTROLLER_FIXED else _rms_scaled(dk, x, y, atol, rtol)
        if err < 1.0:
            for c in range(n):
                x[c] = y[c]
                k1[c] = k3[c]  # stiffly accurate: f(x') = k3 (FSAL)
            done += h
            accepted += 1
            remaining_parts -= 1
            memo[M_FRESH] = 0.0
            if h < hmin:
                hmin = h
            if controller != CONTROLLER_FIXED:
                factor = max_factor if err == 0.0 else min(max_factor, safety * err ** (-1.0 / 3.0))
                proposal = h * max(factor, min_factor)
                memo[M_CARRY] = proposal
                if remaining_parts > 0 and (proposal < h or proposal > 1.5 * h):  # re-plan the rest of the period
                    remaining_parts = max(1, int(math.ceil((period - done) / proposal)))
                    h = (period - done) / remaining_parts
            continue
        rejected += 1
        factor = max(min_factor, safety * err ** (-1.0 / 3.0)) if err == err else min_factor
        remaining = period - done
        remaining_parts = max(remaining_parts + 1, int(math.ceil(remaining / (h * factor))))
        h = remaining / remaining_parts
    memo[M_PARTS] = parts
    _record(plan.stats, k_tick, accepted, rejected, out_int[7] - evals0, hmin)
    return STEP_OK


# ---------------------------------------------------------------------------------------------- plans
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
