"""The fixed-step integrators' arithmetic, written once: compiled in the loop, and behind
:meth:`Integrator.step <coopctrl.integrators.Integrator.step>` of the five built-in schemes.

:func:`zoh_advance` integrates ``dx/dt = f(x, tau)`` over one control period with ``tau`` held,
one step of the chosen scheme per entry ``h_s`` [s] of ``steps`` (``T / substeps`` each, or the
free step of :meth:`ClosedLoop.set_step <coopctrl.closed_loop.ClosedLoop.set_step>`: ``floor(T / h)``
steps and a remainder); the classes of :mod:`coopctrl.integrators` are its configuration:

- an :class:`ExplicitPlan` for ``"euler"``, ``"symplectic_euler"`` and ``"rk4"`` (the scheme is a
  run-time code: the three share one compiled loop): :func:`explicit_period`, the steps stated in
  :func:`_explicit_step`;
- an :class:`ImplicitPlan` for ``"implicit_midpoint"`` and ``"implicit_euler"``: the singly diagonally
  implicit Runge-Kutta step of
  :class:`~coopctrl.integrators.diagonally_implicit.DiagonallyImplicitRungeKutta` (its tableau in the
  plan; :func:`implicit_period`), each stage ``G(k_i) = k_i - f(S_i + gamma h k_i) = 0`` solved by
  simplified Newton with ``M = (I - gamma h J)^-1``: the forward-difference Jacobian
  (:func:`jacobian_into`, increment ``d_j = sqrt(eps) max(|x_j|, 1)`` rounded to a representable
  one), predictors, convergence test, round-off stop, Jacobian reuse (``reuse_rate``) and failure
  (:data:`STEP_NEWTON_FAILED`, which :func:`newton_failure` turns into
  :class:`~coopctrl.integrators.NewtonConvergenceError`). ``M`` and the stage slopes are kept from
  step to step, tick to tick; a new plan starts cold.

One source, two ways to run it. The scheme functions (:func:`explicit_period`, :func:`implicit_period`,
:func:`jacobian_into` and the steps they call) are ``@njit(inline="always")``: numba copies their code
into each compiled caller (the loop's advance stages, :func:`advance_period`) before typing it, and
never compiles them on their own. Python runs the same code, as it is written, when
:meth:`Integrator.step <coopctrl.integrators.Integrator.step>` steps a right-hand side numba cannot call
(any Python ``f(t, x, u)``; ``P`` is then a :class:`coopctrl.integrators.stepping.PythonRightHandSide`
and :func:`rhs_into` calls it at the stage time set by :func:`at_time`): :data:`PYTHON` holds those
functions with each other's names bound to their Python selves.

Why not ``numba.extending.register_jitable`` with ``inline="always"``: numba types such a call by
compiling the function on its own first, to machine code, and then copies its code in anyway; and every
compiled function is optimized together with all it calls. A chain of such wrappers (the stage,
:func:`zoh_advance`, :func:`explicit_period`, :func:`_explicit_step`) optimized the plant's right-hand
side four times on an empty cache, once as it is run. A cooperative plant's ``rhs`` is stepped compiled
(:func:`advance_period`). ``tests/_integrator_oracle.py`` keeps the former numpy arithmetic as an
independent check, itself checked against :func:`scipy.integrate.solve_ivp`.

The scheme family is chosen when numba types the call (the plan's namedtuple class): a scene that
integrates with RK4 never compiles the Newton code. Every work array is in the plan, made once per
run by :func:`make_plan`: a step allocates nothing (the singular-matrix fallback
``numpy.linalg.pinv`` aside).

The plant's right-hand side is ``rhs_into`` of :mod:`plants.cooperative` (spatial or planar, chosen by
the type of the plant's arrays ``P``). numba's disk cache is keyed on every kernel source
(:mod:`plants.numba_cache`): a change here recompiles its callers in other files.
"""

from __future__ import annotations

import math
from collections import namedtuple
from types import FunctionType, SimpleNamespace

import numpy as np
from numba import njit, types
from numba.extending import overload, register_jitable

from coopctrl.integrators.methods import (METHOD_ADAPTIVE, METHOD_EULER, METHOD_RK4, METHOD_SDIRK,  # noqa: F401 (API)
                                          METHOD_SYMPLECTIC_EULER)
from plants.cooperative import _planar_kernel as _pk
from plants.cooperative import _spatial_kernel as _sk
from plants.cooperative.plant_args import is_spatial

# The run-time codes of the schemes (METHOD_EULER, ..., METHOD_ADAPTIVE) are written once, in
# coopctrl.integrators.methods, and imported above.

#: Results of :func:`zoh_advance`.
STEP_OK = 0  #: the period is integrated
STEP_PLANT_ERROR = 1  #: the right-hand side failed (``status`` holds its code, ``x_fail`` the state it was called at)
STEP_TOO_SMALL = 3  #: an error-controlled step fell below ``min_step`` (:mod:`coopctrl.integrators.adaptive_plans`; ``out_float = (step [s], time [s])``)
STEP_NEWTON_FAILED = 2  #: an implicit stage did not converge (``out_int[2:4]``, ``out_float``: see :func:`zoh_advance`)

_EPS = float(np.finfo(float).eps)
_SQRT_EPS = math.sqrt(_EPS)

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


#: How many float64 vectors and matrices a :class:`PlanSlots` holds: the most of any plan family (TR-BDF2's 14
#: vectors; the implicit Runge-Kutta plan's 6 matrices).
SLOT_VECTORS = 14
SLOT_MATRICES = 6

#: A plan of any family in slots of fixed types (see :func:`plan_slots`): ``ints`` int64 ``(1,)`` (an explicit
#: plan's ``method``, else 0), ``vectors`` the plan's float64 ``(k,)`` arrays and ``matrices`` its float64
#: ``(r, c)`` arrays, each in the order of the plan's fields, the unused slots empty.
PlanSlots = namedtuple("PlanSlots", "ints vectors matrices")

_NO_VECTOR = np.zeros(0)
_NO_MATRIX = np.zeros((0, 0))


def plan_slots(plan) -> PlanSlots:
    """``plan`` (:class:`ExplicitPlan`, :class:`ImplicitPlan`, or an error-controlled scheme's
    ``EmbeddedPlan`` or ``TRBDF2Plan``) in slots of the same numba type for every family: the loop's
    compiled tick, which only hands the plan to the plant's advance, is then compiled once for all the
    families, and each family's advance rebuilds its plan from the slots (:func:`explicit_plan_of`,
    :func:`implicit_plan_of`, ``adaptive_plans.embedded_plan_of``, ``adaptive_plans.trbdf2_plan_of``).
    The slots hold the plan's own arrays (no copy): what the advance writes is in ``plan``."""
    ints = np.zeros(1, dtype=np.int64)
    vectors, matrices = [], []
    for value in plan:
        if isinstance(value, np.ndarray) and value.ndim == 1:
            vectors.append(value)
        elif isinstance(value, np.ndarray) and value.ndim == 2:
            matrices.append(value)
        else:  # the explicit plan's method code
            ints[0] = value
    if len(vectors) > SLOT_VECTORS or len(matrices) > SLOT_MATRICES:
        raise TypeError(f"a {type(plan).__name__} does not fit PlanSlots: {len(vectors)} vectors, {len(matrices)} matrices")
    vectors += [_NO_VECTOR] * (SLOT_VECTORS - len(vectors))
    matrices += [_NO_MATRIX] * (SLOT_MATRICES - len(matrices))
    return PlanSlots(ints, tuple(vectors), tuple(matrices))


@register_jitable
def explicit_plan_of(slots):
    """The :class:`ExplicitPlan` held in ``slots`` (:func:`plan_slots`), its own arrays."""
    v = slots.vectors
    return ExplicitPlan(slots.ints[0], v[0], v[1], v[2], v[3], v[4])


@register_jitable
def implicit_plan_of(slots):
    """The :class:`ImplicitPlan` held in ``slots`` (:func:`plan_slots`), its own arrays."""
    v, mat = slots.vectors, slots.matrices
    return ImplicitPlan(v[0], mat[0], v[1], v[2], mat[1], mat[2], mat[3], mat[4], mat[5], v[3], v[4], v[5], v[6],
                        v[7], v[8], v[9], v[10])


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


def newton_failure(scheme: str, steps, out_int, out_float):
    """The :class:`~coopctrl.integrators.NewtonConvergenceError` of a :func:`zoh_advance` that returned
    :data:`STEP_NEWTON_FAILED` on the period ``steps``, from its outputs."""
    from coopctrl.integrators import NewtonConvergenceError

    return NewtonConvergenceError(float(out_float[1]), float(out_float[0]), int(out_int[3]),
                                  float(steps[int(out_int[2])]), scheme)


# ---------------------------------------------------------------------------------------------- plant
def rhs_into(x, tau, P, status, ws, dx):
    """The plant's right-hand side into ``dx`` (the allocation-free ``rhs_into`` of
    ``plants.cooperative``), compiled for the spatial or the planar kernel by the type of ``P``'s
    bases (``(m, 4, 4)`` spatial, ``(m, 3)`` planar). ``P`` = ``CooperativePlant.plant_args``
    (:class:`~plants.cooperative.plant_args.PlantArgs`).

    Called from Python (the scheme functions run as they are): ``P`` is a
    :class:`~coopctrl.integrators.stepping.PythonRightHandSide` (a Python ``f(t, x, u)``), or the
    plant's kernel arrays (their compiled ``rhs_into_packed``)."""
    if isinstance(P, tuple):
        (_sk if is_spatial(P) else _pk).rhs_into_packed(x, tau, P, status, ws, dx)
    else:
        P.evaluate(x, tau, status, dx)


def at_time(P, t):
    """The time [s] of the next :func:`rhs_into` calls: a Python ``f(t, x, u)`` is called at the stage
    time (``P.t = t``); the plant is autonomous, so compiled this is nothing."""
    if not isinstance(P, tuple):
        P.t = t


@overload(at_time)
def _at_time_typed(P, t):
    def impl(P, t):
        pass
    return impl


@overload(rhs_into)
def _rhs_into_typed(x, tau, P, status, ws, dx):
    # the packed entry point: P passes whole, and is unpacked where nothing is reference-counted
    kernel = _sk.rhs_into_packed if is_spatial(P) else _pk.rhs_into_packed

    def impl(x, tau, P, status, ws, dx):
        kernel(x, tau, P, status, ws, dx)
    return impl


def first_rhs_into(x, tau, P, status, ws, terms, dx):
    """:func:`rhs_into` at the state whose control terms ``terms`` holds: a spatial plant finishes the
    right-hand side from them (``rhs_from_terms_into``: no second arm pass, the same bits); a planar
    plant, or ``terms = None``, evaluates it afresh (from Python too)."""
    rhs_into(x, tau, P, status, ws, dx)


@overload(first_rhs_into)
def _first_rhs_into_typed(x, tau, P, status, ws, terms, dx):
    if terms is not None and not isinstance(terms, types.NoneType) and is_spatial(P):
        def impl(x, tau, P, status, ws, terms, dx):
            _sk.rhs_from_terms_into(x, tau, P, status, terms, dx)
        return impl

    def impl(x, tau, P, status, ws, terms, dx):
        rhs_into(x, tau, P, status, ws, dx)
    return impl


@njit(inline="always")
def copy_into(dst, src):
    """``dst[:] = src`` as a loop: a slice assignment needs numba's reference counting, which the explicit and
    error-controlled advance stages are compiled without."""
    for c in range(src.shape[0]):
        dst[c] = src[c]


@njit(inline="always")
def stage_failed(y, status, x_fail, out_int) -> bool:
    """After one right-hand-side evaluation at ``y``: count it (``out_int[7]``, the run's evaluations) and
    tell whether the plant failed there (``status[0] != 0``), keeping ``y`` in ``x_fail`` for the diagnosis."""
    out_int[7] += 1
    if status[0] != 0:
        copy_into(x_fail, y)
        return True
    return False


# ---------------------------------------------------------------------------------------------- period
def zoh_advance(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
    """Advance ``x`` in place over one control period from ``t`` [s], one step per entry of ``steps`` [s].

    Args:
        plan: An :class:`ExplicitPlan` or :class:`ImplicitPlan` (:func:`make_plan`); the implicit
            plan's Newton state is updated.
        x: float64 ``(nx,)``: the state at ``t``, on return the state at ``t + sum(steps)`` (on a
            failure: partly advanced; the caller restores it).
        tau: The held inputs.
        P, status, ws: The plant's kernel arrays, its int64 ``(2,)`` status and its workspace.
        terms: The control workspace holding the plant's terms at ``x`` (the tick's sensors at the true
            state), or ``None``. An explicit scheme's first right-hand side of the period then reuses
            them (:func:`first_rhs_into`: the same bits, one arm pass fewer); the implicit ones ignore it.
        t: Time [s] at the start of the period (the implicit schemes' failure time counts from it).
        steps: float64: the steps [s] of the period.
        x_fail: Out: the state the right-hand side failed at (:data:`STEP_PLANT_ERROR`).
        out_int: ``out_int[7]`` counts the right-hand-side evaluations; on :data:`STEP_NEWTON_FAILED`
            ``out_int[2]`` = the index of the failed step in ``steps``, ``out_int[3]`` = the Newton
            iterations of the failed stage.
        out_float: On :data:`STEP_NEWTON_FAILED`: ``(last Newton correction, time [s] at the start of
            the failed step)``.

    Returns:
        :data:`STEP_OK`, :data:`STEP_PLANT_ERROR` or :data:`STEP_NEWTON_FAILED`.

    Called from Python (an explicit or implicit plan), the same scheme functions run as they are: the
    step of :meth:`Integrator.step <coopctrl.integrators.Integrator.step>` on a Python ``f``.
    """
    if type(plan) is ImplicitPlan:
        return PYTHON.implicit_period(plan, x, tau, P, status, ws, t, steps, x_fail, out_int, out_float)
    if type(plan) is ExplicitPlan:
        return PYTHON.explicit_period(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int)
    raise TypeError(f"plan is a {type(plan).__name__}: from Python, zoh_advance steps an ExplicitPlan or an "
                    "ImplicitPlan (the error-controlled plans run compiled: advance_period)")


@overload(zoh_advance)
def _zoh_advance_typed(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
    if getattr(plan, "instance_class", None) is ImplicitPlan:
        def impl(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
            return implicit_period(plan, x, tau, P, status, ws, t, steps, x_fail, out_int, out_float)
        return impl
    if getattr(plan, "instance_class", None) is ExplicitPlan:
        def impl(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
            return explicit_period(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int)
        return impl
    import coopctrl.integrators.adaptive_plans as _adaptive

    if getattr(plan, "instance_class", None) is _adaptive.EmbeddedPlan:
        def impl(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
            return _adaptive.embedded_advance(plan, x, tau, P, status, ws, terms, t, x_fail, out_int, out_float)
        return impl
    if getattr(plan, "instance_class", None) is _adaptive.TRBDF2Plan:
        def impl(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int, out_float):
            return _adaptive.trbdf2_advance(plan, x, tau, P, status, ws, terms, t, x_fail, out_int, out_float)
        return impl
    return None


@njit(cache=True)
def advance_period(plan, x, tau, P, status, ws, t, steps, x_fail, out_int, out_float):
    """:func:`zoh_advance` compiled, callable from Python with the plant's kernel arrays ``P``
    (:meth:`Integrator.step <coopctrl.integrators.Integrator.step>` on a plant's ``rhs``, tests)."""
    return zoh_advance(plan, x, tau, P, status, ws, None, t, steps, x_fail, out_int, out_float)


# ---------------------------------------------------------------------------------------------- explicit
@njit(inline="always")
def explicit_period(plan, x, tau, P, status, ws, terms, t, steps, x_fail, out_int):
    """An :class:`ExplicitPlan` over the steps ``steps`` [s] from ``t`` [s] (:func:`zoh_advance`)."""
    ts = t
    for si in range(steps.shape[0]):
        hs = steps[si]
        code = _explicit_step(plan, x, tau, P, status, ws, terms, si == 0, ts, hs, x_fail, out_int)
        if code != STEP_OK:
            return code
        ts += hs
    return STEP_OK


@njit(inline="always")
def _explicit_step(plan, x, tau, P, status, ws, terms, first, t, hs, x_fail, out_int):
    """One step of ``plan.method`` from ``t`` [s]:

    - euler: ``x' = x + h f(t, x)``;
    - symplectic_euler: ``dz' = dz + h ddz(t, x)``, then ``z' = z + h dz'``;
    - rk4: ``k1 = f(t, x)``, ``k2 = f(t + h/2, x + h/2 k1)``, ``k3 = f(t + h/2, x + h/2 k2)``,
      ``k4 = f(t + h, x + h k3)``, ``x' = x + h/6 ((k2 + k3) 2 + k1 + k4)``.

    The first step of a period (``first``) takes its first right-hand side from ``terms``
    (:func:`first_rhs_into`)."""
    k1, k2, k3, k4, y = plan.k1, plan.k2, plan.k3, plan.k4, plan.y
    nx = x.shape[0]
    nz = nx // 2
    method = plan.method
    at_time(P, t)
    if first:  # every explicit scheme starts from the slope at x
        first_rhs_into(x, tau, P, status, ws, terms, k1)
    else:
        rhs_into(x, tau, P, status, ws, k1)
    if stage_failed(x, status, x_fail, out_int):
        return STEP_PLANT_ERROR
    if method == METHOD_RK4:
        h2 = 0.5 * hs
        for c in range(nx):
            y[c] = k1[c] * h2 + x[c]
        at_time(P, t + h2)
        rhs_into(y, tau, P, status, ws, k2)
        if stage_failed(y, status, x_fail, out_int):
            return STEP_PLANT_ERROR
        for c in range(nx):
            y[c] = k2[c] * h2 + x[c]
        rhs_into(y, tau, P, status, ws, k3)
        if stage_failed(y, status, x_fail, out_int):
            return STEP_PLANT_ERROR
        for c in range(nx):
            y[c] = k3[c] * hs + x[c]
        at_time(P, t + hs)
        rhs_into(y, tau, P, status, ws, k4)
        if stage_failed(y, status, x_fail, out_int):
            return STEP_PLANT_ERROR
        h6 = hs / 6.0
        for c in range(nx):
            x[c] = ((((k2[c] + k3[c]) * 2.0) + k1[c]) + k4[c]) * h6 + x[c]
    elif method == METHOD_SYMPLECTIC_EULER:
        for c in range(nz):
            x[nz + c] = k1[nz + c] * hs + x[nz + c]
        for c in range(nz):
            x[c] = x[nz + c] * hs + x[c]
    else:
        for c in range(nx):
            x[c] = k1[c] * hs + x[c]
    return STEP_OK


# ---------------------------------------------------------------------------------------------- implicit
@njit(cache=True)
def _max_abs(v):
    """``max |v_c|`` as ``float(np.abs(v).max())``: NaN if any entry is NaN."""
    m = 0.0
    for c in range(v.shape[0]):
        a = abs(v[c])
        if a > m or a != a:
            m = a
            if a != a:
                return a
    return m


@njit(cache=True)
def invert_into(A, LU, M):
    """``M = A^-1`` by LU factorization with partial pivoting (``LU`` receives the factors).

    Returns False, leaving ``M`` undefined, when a pivot is exactly zero (where LAPACK's ``getrf``
    reports a singular matrix and ``numpy.linalg.inv`` raises). Allocates nothing.
    """
    n = A.shape[0]
    for r in range(n):
        for c in range(n):
            LU[r, c] = A[r, c]
            M[r, c] = 0.0
        M[r, r] = 1.0
    for j in range(n):
        p = j
        best = abs(LU[j, j])
        for r in range(j + 1, n):
            v = abs(LU[r, j])
            if v > best:
                best = v
                p = r
        if LU[p, j] == 0.0:
            return False
        if p != j:  # swap rows of the factors and of the right-hand side P I
            for c in range(n):
                LU[j, c], LU[p, c] = LU[p, c], LU[j, c]
                M[j, c], M[p, c] = M[p, c], M[j, c]
        piv = LU[j, j]
        for r in range(j + 1, n):
            lrj = LU[r, j] / piv
            LU[r, j] = lrj
            if lrj != 0.0:
                for c in range(j + 1, n):
                    LU[r, c] -= lrj * LU[j, c]
                for c in range(n):
                    M[r, c] -= lrj * M[j, c]
    for r in range(n - 1, -1, -1):  # back substitution U X = L^-1 P I, all columns at once
        for j in range(r + 1, n):
            u = LU[r, j]
            if u != 0.0:
                for c in range(n):
                    M[r, c] -= u * M[j, c]
        d = LU[r, r]
        for c in range(n):
            M[r, c] /= d
    return True


@njit(cache=True)
def _pinv_into(A, M):
    """``M = pinv(A)`` (the fallback for a singular ``I - gamma h J``); NaN when ``A`` is not finite
    (Newton then fails on a non-finite correction)."""
    for r in range(A.shape[0]):
        for c in range(A.shape[1]):
            if not math.isfinite(A[r, c]):
                M[:, :] = np.nan
                return
    M[:, :] = np.linalg.pinv(A)


@njit(inline="always")
def jacobian_into(J, x, tau, P, status, ws, fx, xp, fp, out_int, x_fail):
    """``J = df/dx`` at ``x`` (``fx = f(x)``) by forward differences: column ``j`` is
    ``(f(x + d_j e_j) - fx) / d_j`` with ``d_j = sqrt(eps) max(|x_j|, 1)`` rounded to a representable
    increment; ``xp``, ``fp`` (nx,) work. Returns False on a right-hand-side failure (``x_fail`` set)."""
    n = x.shape[0]
    for c in range(n):
        xp[c] = x[c]
    for j in range(n):
        xj = x[j]
        d = _SQRT_EPS * max(abs(xj), 1.0)
        xp[j] = xj + d
        d = xp[j] - xj  # exactly representable increment
        rhs_into(xp, tau, P, status, ws, fp)
        if stage_failed(xp, status, x_fail, out_int):
            return False
        for r in range(n):
            J[r, j] = (fp[r] - fx[r]) / d
        xp[j] = xj
    return True


@njit(inline="always")
def _refresh(plan, x, tau, P, status, ws, fx, gh, out_int, x_fail):
    """``plan.M = (I - gh J)^-1`` with ``J`` the forward-difference Jacobian at ``x`` (``fx = f(x)``):
    column ``j`` is ``(f(x + d_j e_j) - fx) / d_j``.
    Returns False on a right-hand-side failure (``x_fail`` set)."""
    A = plan.A
    n = x.shape[0]
    plan.memo[2] += 1.0
    if not jacobian_into(A, x, tau, P, status, ws, fx, plan.xp, plan.fp, out_int, x_fail):
        return False
    for r in range(n):
        for j in range(n):
            A[r, j] = (1.0 if r == j else 0.0) - gh * A[r, j]
    if not invert_into(A, plan.LU, plan.M):
        _pinv_into(A, plan.M)
    return True


@njit(inline="always")
def implicit_period(plan, x, tau, P, status, ws, t, steps, x_fail, out_int, out_float):
    """An :class:`ImplicitPlan` over the steps ``steps`` [s] from ``t`` [s] (:func:`zoh_advance`)."""
    ts = t
    for si in range(steps.shape[0]):
        hs = steps[si]
        code, iterations, correction = _sdirk_step(plan, x, tau, P, status, ws, ts, hs, x_fail, out_int)
        if code == STEP_NEWTON_FAILED:
            out_int[2] = si
            out_int[3] = iterations
            out_float[0] = correction
            out_float[1] = ts
        if code != STEP_OK:
            return code
        ts += hs
    return STEP_OK


@njit(inline="always")
def _sdirk_step(plan, x, tau, P, status, ws, t, h, x_fail, out_int):
    """One step of the diagonally implicit Runge-Kutta scheme of
    :class:`~coopctrl.integrators.DiagonallyImplicitRungeKutta` on ``x`` in place (its docstring states
    the stages, the simplified Newton iteration, the Jacobian reuse and the stopping tests).

    Returns ``(code, iterations, correction)``: :data:`STEP_OK`, :data:`STEP_PLANT_ERROR` or
    :data:`STEP_NEWTON_FAILED` with the failed stage's iterations and last correction
    ``h max|dk|`` (the arguments of ``NewtonConvergenceError``).
    """
    rtol, atol = plan.settings[0], plan.settings[1]
    max_iterations = int(plan.settings[2])
    reuse_rate = plan.settings[3]
    tableau, weights, nodes = plan.tableau, plan.weights, plan.nodes
    M, slopes, predictors, memo = plan.M, plan.slopes, plan.predictors, plan.memo
    known, k, xs, fs, dk = plan.known, plan.k, plan.xs, plan.fs, plan.dk
    n = x.shape[0]
    s = tableau.shape[0]
    gamma = tableau[0, 0]
    # a matrix made for another step, or dropped after a slow step: cold start (no predictors)
    have_M = memo[0] != 0.0 and memo[1] == h
    warm = have_M
    gh = gamma * h
    fresh = False  # M was evaluated during this step
    slow = False  # some stage converged slower than reuse_rate
    xmax = _max_abs(x)
    tol = atol + rtol * xmax
    for i in range(s):
        ts = t + nodes[i] * h
        for c in range(n):  # S_i = x + h sum_{j<i} a_ij k_j
            known[c] = x[c]
        for j in range(i):
            a = tableau[i, j]
            if a != 0.0:
                ah = a * h
                for c in range(n):
                    known[c] += ah * slopes[j, c]
        if warm:
            for c in range(n):
                k[c] = predictors[i, c]
        elif i == 0:  # explicit slope as predictor
            at_time(P, t)
            rhs_into(x, tau, P, status, ws, k)
            if stage_failed(x, status, x_fail, out_int):
                return STEP_PLANT_ERROR, 0, 0.0
        else:
            for c in range(n):
                k[c] = slopes[i - 1, c]
        previous = math.inf
        rate = 0.0
        total = 0
        while True:
            for c in range(n):
                xs[c] = k[c] * gh + known[c]
            at_time(P, ts)
            rhs_into(xs, tau, P, status, ws, fs)
            if stage_failed(xs, status, x_fail, out_int):
                return STEP_PLANT_ERROR, 0, 0.0
            if not have_M:
                if not _refresh(plan, xs, tau, P, status, ws, fs, gh, out_int, x_fail):
                    return STEP_PLANT_ERROR, 0, 0.0
                memo[0] = 1.0
                memo[1] = h
                have_M = True
                fresh = True
                previous = math.inf
            for r in range(n):  # dk = M (k - fs)
                acc = 0.0
                for c in range(n):
                    acc += M[r, c] * (k[c] - fs[c])
                dk[r] = acc
            for c in range(n):
                k[c] -= dk[c]
            total += 1
            correction = h * _max_abs(dk)
            if correction <= tol or correction <= tol + rtol * h * _max_abs(k):
                break
            if not math.isfinite(correction):
                if fresh:
                    memo[0] = 0.0
                    return STEP_NEWTON_FAILED, total, correction
                at_time(P, t)
                rhs_into(x, tau, P, status, ws, k)  # the stale matrix threw the iterate away: restart
                if stage_failed(x, status, x_fail, out_int):
                    return STEP_PLANT_ERROR, 0, 0.0
                have_M = False
                continue
            rate = correction / previous
            hk = h * _max_abs(k)
            if fresh and rate > 0.5 and correction <= _SQRT_EPS * (hk if hk > xmax else xmax):
                break  # stagnating at the round-off floor of f: as converged as it can be
            if total >= max_iterations:
                memo[0] = 0.0
                return STEP_NEWTON_FAILED, total, correction
            if rate > reuse_rate:
                have_M = False  # slow: re-evaluate the Jacobian at the current iterate
            previous = correction
        slow = slow or not (total <= 2 or rate <= reuse_rate)
        for c in range(n):
            slopes[i, c] = k[c]
    if slow:
        memo[0] = 0.0  # slow this step: refresh at the start of the next one
    for i in range(s):
        for c in range(n):
            predictors[i, c] = slopes[i, c]
    for i in range(s):
        bh = weights[i] * h
        for c in range(n):
            x[c] += bh * slopes[i, c]
    return STEP_OK, 0, 0.0


def _python_functions(namespace: dict, names) -> SimpleNamespace:
    """The functions ``names`` of ``namespace`` (``@njit(inline="always")`` dispatchers, which numba only
    copies into compiled callers) as plain Python functions of the same code, each calling the others'
    Python selves by their names."""
    bound = dict(namespace)
    for name in names:
        f = namespace[name].py_func
        bound[name] = FunctionType(f.__code__, bound, f.__name__, f.__defaults__, f.__closure__)
    return SimpleNamespace(**{name: bound[name] for name in names})


#: The scheme functions as Python runs them (:func:`zoh_advance` called from Python, on a Python ``f``):
#: their own code, calling each other in Python.
PYTHON = _python_functions(globals(), ("stage_failed", "explicit_period", "_explicit_step", "jacobian_into",
                                       "_refresh", "implicit_period", "_sdirk_step"))
