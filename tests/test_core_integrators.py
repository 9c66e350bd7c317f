"""coopctrl/core's fixed-step schemes (explicit_schemes.h, implicit_schemes.h; coopctrl._core.zoh_advance on a
Python right-hand side) against the numpy oracle of tests/_integrator_oracle.py (itself checked against scipy):
the explicit schemes bit for bit (the oracle repeats their operations element by element), the implicit ones to
their Newton tolerance, over several periods of several steps (the implicit plans' Newton state carried from
period to period); the Newton failure reported as the oracle's exception; the LU inverse and the pseudo-inverse
against numpy. (The schemes were checked bit for bit against the numba arithmetic they replaced when they were
ported; the golden records lock a run's numbers since.)"""

from __future__ import annotations

import numpy as np
import pytest

from _integrator_oracle import EXPLICIT, SDIRK
from coopctrl import _core
from coopctrl.integrators import NewtonConvergenceError, get_integrator
from coopctrl.integrators import compiled

SCHEMES = ["euler", "symplectic_euler", "rk4", "implicit_midpoint", "implicit_euler"]


def _pendulums(t, x, u):
    """Two coupled damped pendulums (z = two angles [rad]), driven by u [N m] and a time-varying term: a nonlinear
    f(t, x, u) -> (dz, ddz)."""
    q, dq = x[:2], x[2:]
    ddq = np.array([-9.81 * np.sin(q[0]) + 2.0 * (q[1] - q[0]) - 0.3 * dq[0] + u[0] + 0.1 * np.cos(3.0 * t),
                    -9.81 * np.sin(q[1]) - 2.0 * (q[1] - q[0]) - 0.3 * dq[1] + u[1]])
    return np.concatenate([dq, ddq])


def _counted(f):
    """``f`` and its call count (a list of one)."""
    calls = [0]

    def g(t, x, u):
        calls[0] += 1
        return f(t, x, u)

    return g, calls


def _run_against_oracle(scheme_name, f, x0, tau, steps, periods):
    """``periods`` periods of ``steps`` by the core and by the oracle, one step at a time, from ``x0``: the largest
    difference of the states after each period, and the implicit scheme's Newton tolerance per step."""
    scheme = get_integrator(scheme_name)
    plan = compiled.make_plan(scheme, x0.shape[0])
    oracle = EXPLICIT.get(scheme_name) or SDIRK(get_integrator(scheme_name)).step
    g, calls = _counted(f)  # one function for every step: the implicit oracle keeps its matrix for it
    x, y, diff = x0.copy(), x0.copy(), 0.0
    for k in range(periods):
        t = k * float(np.sum(steps))
        got = _core.zoh_advance(plan, f, x, tau, t, steps, np.zeros_like(x0))
        assert got["code"] == compiled.STEP_OK
        before = calls[0]
        for h in steps:
            y = oracle(g, t, y, tau, float(h))
            t += float(h)
        assert got["rhs_evaluations"] == calls[0] - before
        diff = max(diff, float(np.abs(x - y).max()))
    tol = getattr(scheme, "atol", 0.0) + getattr(scheme, "rtol", 0.0) * float(np.abs(y).max())
    return diff, tol


@pytest.mark.parametrize("scheme", SCHEMES)
def test_the_schemes_match_the_oracle(scheme):
    """Explicit: the same bits. Implicit: the same iteration path (the same right-hand-side count, Jacobian columns
    included) and states within the Newton tolerance per step, summed over the steps (the schemes are A-stable: an
    earlier difference does not grow; the LU inverse and the products round differently from LAPACK and BLAS)."""
    rng = np.random.default_rng(7)
    steps = np.array([2.5e-3, 2.5e-3, 2.5e-3, 1.0e-3])  # a free step: floor(T / h) steps and a remainder
    periods = 40
    for _ in range(3):
        x0 = rng.uniform(-1.0, 1.0, 4)
        tau = rng.uniform(-2.0, 2.0, 2)
        diff, tol = _run_against_oracle(scheme, _pendulums, x0, tau, steps, periods)
        if scheme in EXPLICIT:
            assert diff == 0.0
        else:
            assert diff <= len(steps) * periods * tol, (diff, tol)


def test_a_newton_failure_is_reported_as_the_oracle_one():
    """A stiff f (rate 1e7 1/s) whose Newton iteration is capped at two iterations fails on its first stage: the
    oracle's exception's time, step and iterations, and its last correction to 1e-9 relative (the paths' rounding
    differs in its last digits)."""
    def stiff(t, x, u):
        return np.array([x[1], -1e7 * np.sinh(x[0]) - 1e3 * x[1]])

    scheme = get_integrator("implicit_euler", max_iterations=2)
    x0 = np.array([0.5, 0.0])
    steps = np.array([1e-2])
    got = _core.zoh_advance(compiled.make_plan(scheme, 2), stiff, x0.copy(), np.zeros(1), 0.0, steps, np.zeros(2))
    with pytest.raises(NewtonConvergenceError) as info:
        SDIRK(get_integrator("implicit_euler", max_iterations=2)).step(stiff, 0.0, x0.copy(), np.zeros(1), 1e-2)
    want = info.value
    assert got["code"] == compiled.STEP_NEWTON_FAILED
    assert (got["failed_time"], steps[got["failed_step"]], got["newton_iterations"]) == (want.time, want.step,
                                                                                         want.iterations)
    assert got["last_correction"] == pytest.approx(want.value, rel=1e-9)


def test_a_python_exception_in_f_reaches_the_caller():
    def broken(t, x, u):
        raise ZeroDivisionError("f failed")

    plan = compiled.make_plan(get_integrator("rk4"), 2)
    with pytest.raises(ZeroDivisionError, match="f failed"):
        _core.zoh_advance(plan, broken, np.zeros(2), np.zeros(1), 0.0, np.array([1e-3]), np.zeros(2))
    with pytest.raises(ValueError, match=r"returned shape \(3,\): expected \(2,\)"):
        _core.zoh_advance(plan, lambda t, x, u: np.zeros(3), np.zeros(2), np.zeros(1), 0.0, np.array([1e-3]),
                          np.zeros(2))


def test_the_inverse_and_the_pseudo_inverse_match_numpy():
    rng = np.random.default_rng(11)
    for n in (1, 3, 8, 20):
        A = rng.normal(size=(n, n))
        M = np.empty((n, n))
        _core.inverse(A, M)
        np.testing.assert_allclose(M @ A, np.eye(n), atol=1e-11 * np.linalg.cond(A))
        # rank-deficient: the SVD's pseudo-inverse to rounding (different algorithms: LAPACK's divide and
        # conquer against one-sided Jacobi), relative to its largest entry
        B = A.copy()
        if n > 1:
            B[-1] = B[0] * 2.0
        _core.pseudo_inverse(B, M)
        want = np.linalg.pinv(B, rcond=1e-15)
        np.testing.assert_allclose(M, want, rtol=0, atol=1e-9 * np.max(np.abs(want)))
    singular = np.zeros((3, 3))
    with pytest.raises(ValueError, match="singular"):
        _core.inverse(singular, np.empty((3, 3)))
    M = np.empty((2, 2))
    _core.pseudo_inverse(np.array([[np.nan, 0.0], [0.0, 1.0]]), M)
    assert np.isnan(M).all()
