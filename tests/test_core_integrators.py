"""coopctrl/core's fixed-step schemes (explicit_schemes.h, implicit_schemes.h; coopctrl._core.zoh_advance on a
Python right-hand side): bit for bit the arithmetic of coopctrl.integrators.compiled, which Python runs on the same
f, for every scheme, over several periods of several steps (the implicit plans' Newton state carried from period to
period); the Newton failure reported with the same fields; the LU inverse and the pseudo-inverse against numpy."""

from __future__ import annotations

import numpy as np
import pytest

from coopctrl import _core
from coopctrl.integrators import get_integrator
from coopctrl.integrators import compiled
from coopctrl.integrators.stepping import PythonRightHandSide

SCHEMES = ["euler", "symplectic_euler", "rk4", "implicit_midpoint", "implicit_euler"]


def _pendulums(t, x, u):
    """Two coupled damped pendulums (z = two angles [rad]), driven by u [N m] and a time-varying term: a nonlinear
    f(t, x, u) -> (dz, ddz)."""
    q, dq = x[:2], x[2:]
    ddq = np.array([-9.81 * np.sin(q[0]) + 2.0 * (q[1] - q[0]) - 0.3 * dq[0] + u[0] + 0.1 * np.cos(3.0 * t),
                    -9.81 * np.sin(q[1]) - 2.0 * (q[1] - q[0]) - 0.3 * dq[1] + u[1]])
    return np.concatenate([dq, ddq])


def _run_both(scheme_name, f, x0, tau, steps, periods):
    scheme = get_integrator(scheme_name)
    plans = [compiled.make_plan(scheme, x0.shape[0]) for _ in range(2)]
    states = [x0.copy(), x0.copy()]
    for k in range(periods):
        t = k * float(np.sum(steps))
        out_int, out_float = np.zeros(8, np.int64), np.zeros(2)
        x_fail = [np.zeros_like(x0), np.zeros_like(x0)]
        want = compiled.zoh_advance(plans[0], states[0], tau, PythonRightHandSide(f), np.zeros(2, np.int64), None,
                                    None, t, steps, x_fail[0], out_int, out_float)
        got = _core.zoh_advance(plans[1], f, states[1], tau, t, steps, x_fail[1])
        assert got["code"] == want
        assert got["rhs_evaluations"] == out_int[7]
        if want == compiled.STEP_NEWTON_FAILED:
            assert (got["failed_step"], got["newton_iterations"]) == (out_int[2], out_int[3])
            assert (got["last_correction"], got["failed_time"]) == (out_float[0], out_float[1])
        np.testing.assert_array_equal(states[1], states[0])
        for a, b in zip(plans[1], plans[0]):
            np.testing.assert_array_equal(a, b)
        if want != compiled.STEP_OK:
            return want
    return compiled.STEP_OK


@pytest.mark.parametrize("scheme", SCHEMES)
def test_the_schemes_match_the_python_arithmetic_bit_for_bit(scheme):
    rng = np.random.default_rng(7)
    for _ in range(3):
        x0 = rng.uniform(-1.0, 1.0, 4)
        tau = rng.uniform(-2.0, 2.0, 2)
        steps = np.array([2.5e-3, 2.5e-3, 2.5e-3, 1.0e-3])  # a free step: floor(T / h) steps and a remainder
        assert _run_both(scheme, _pendulums, x0, tau, steps, periods=40) == compiled.STEP_OK


def test_a_newton_failure_is_reported_as_the_python_one():
    """A stiff f (rate 1e7 1/s) whose Newton iteration is capped at two iterations fails on its first stage."""
    def stiff(t, x, u):
        return np.array([x[1], -1e7 * np.sinh(x[0]) - 1e3 * x[1]])

    scheme = get_integrator("implicit_euler", max_iterations=2)
    x0 = np.array([0.5, 0.0])
    plans = [compiled.make_plan(scheme, 2) for _ in range(2)]
    steps = np.array([1e-2])
    out_int, out_float = np.zeros(8, np.int64), np.zeros(2)
    states, fails = [x0.copy(), x0.copy()], [np.zeros(2), np.zeros(2)]
    want = compiled.zoh_advance(plans[0], states[0], np.zeros(1), PythonRightHandSide(stiff), np.zeros(2, np.int64),
                                None, None, 0.0, steps, fails[0], out_int, out_float)
    got = _core.zoh_advance(plans[1], stiff, states[1], np.zeros(1), 0.0, steps, fails[1])
    assert want == compiled.STEP_NEWTON_FAILED
    assert got["code"] == want
    assert (got["failed_step"], got["newton_iterations"]) == (out_int[2], out_int[3])
    assert (got["last_correction"], got["failed_time"]) == (out_float[0], out_float[1])


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
