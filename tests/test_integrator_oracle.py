"""The numpy oracle of the integrators (``tests/_integrator_oracle.py``) against independent references:
scipy's ``solve_ivp`` on a nonlinear pendulum (the order of each scheme) and the analytic one-step map
of a damped linear oscillator. ``tests/test_integrators_compiled.py`` checks the package's one source
(:mod:`coopctrl.integrators.compiled`) against this oracle."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from _integrator_oracle import EXPLICIT, SDIRK
from coopctrl.integrators import ImplicitEuler, ImplicitMidpoint

ORDERS = {"euler": 1, "symplectic_euler": 1, "rk4": 4, "implicit_midpoint": 2, "implicit_euler": 1}
#: ``R(z)`` of each scheme on ``dx/dt = lambda x`` (symplectic Euler has none: see its own test).
STABILITY = {
    "euler": lambda z: 1 + z,
    "rk4": lambda z: 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24,
    "implicit_midpoint": lambda z: (1 + z / 2) / (1 - z / 2),
    "implicit_euler": lambda z: 1 / (1 - z),
}


def _oracle(name):
    if name in EXPLICIT:
        return EXPLICIT[name]
    return SDIRK(ImplicitMidpoint() if name == "implicit_midpoint" else ImplicitEuler()).step


def _pendulum(t, x, u):
    """A damped, forced pendulum: ``ddq = -9.81 sin q - 0.2 dq + u cos(2 t)`` (time-dependent)."""
    return np.array([x[1], -9.81 * math.sin(x[0]) - 0.2 * x[1] + u * math.cos(2.0 * t)])


@pytest.fixture(scope="module")
def reference():
    """scipy's DOP853 at rtol 1e-12, atol 1e-14 over 1 s: its error (~1e-12) is far below the schemes'
    errors at the steps used (above 1e-9), so the measured slopes are the schemes'."""
    sol = solve_ivp(lambda t, y: _pendulum(t, y, 0.5), (0.0, 1.0), [1.2, 0.0], method="DOP853", rtol=1e-12,
                    atol=1e-14)
    assert sol.status == 0
    return sol.y[:, -1]


@pytest.mark.parametrize("name", list(ORDERS))
def test_oracle_converges_at_its_order_to_solve_ivp(name, reference):
    """The error at t = 1 s against scipy falls as ``h^order``: the slope of log(error) over log(h) for
    h = 1/40 .. 1/160 within 0.25 of the order (the asymptotic regime is reached there; measured slopes
    are within 0.1 for every scheme)."""
    errors = []
    steps = (40, 80, 160)
    for n in steps:
        step, x, h = _oracle(name), np.array([1.2, 0.0]), 1.0 / n
        for k in range(n):
            x = step(_pendulum, k * h, x, 0.5, h)
        errors.append(np.abs(x - reference).max())
    slope = np.polyfit(np.log([1.0 / n for n in steps]), np.log(errors), 1)[0]
    assert abs(slope - ORDERS[name]) <= 0.25, (slope, errors)


@pytest.mark.parametrize("name", list(STABILITY))
def test_oracle_one_step_map_is_the_analytic_stability_function(name):
    """On ``dx/dt = L x`` (omega = 20 rad/s, zeta = 0.1) one step from each unit vector is ``R(h L)``
    (``R`` of the scheme, through L's eigenvalues), to 1e-10: the implicit ones solve to a Newton tolerance
    of 1e-12 relative with a finite-difference Jacobian (exact up to ~1e-8 here: it only slows Newton)."""
    L = np.array([[0.0, 1.0], [-400.0, -4.0]])
    h = 0.01 if name in EXPLICIT else 0.3  # within the explicit limits; far beyond them for the implicit
    w, V = np.linalg.eig(L)
    expected = (V @ np.diag(STABILITY[name](h * w)) @ np.linalg.inv(V)).real
    step = _oracle(name)
    got = np.column_stack([step(lambda t, x, u: L @ x, 0.0, e, None, h) for e in np.eye(2)])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-10)


def test_symplectic_euler_oracle_is_its_one_step_matrix():
    """Symplectic Euler on ``ddz = -omega^2 z - 2 zeta omega dz``: ``[[1 - c^2, h (1 - 2 zeta c)], [-h omega^2,
    1 - 2 zeta c]]`` with ``c = h omega`` (exact up to rounding, 1e-14), and over many steps it follows the
    exact flow ``expm(L t)`` to first order (error halves with h within 15 %)."""
    omega, zeta, h = 20.0, 0.1, 0.01
    c = h * omega
    L = np.array([[0.0, 1.0], [-omega**2, -2.0 * zeta * omega]])
    f = lambda t, x, u: L @ x  # noqa: E731
    got = np.column_stack([EXPLICIT["symplectic_euler"](f, 0.0, e, None, h) for e in np.eye(2)])
    expected = np.array([[1 - c * c, h * (1 - 2 * zeta * c)], [-h * omega**2, 1 - 2 * zeta * c]])
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-14)
    errors = []
    for n in (400, 800):
        x = np.array([1.0, 0.0])
        for _ in range(n):
            x = EXPLICIT["symplectic_euler"](f, 0.0, x, None, 1.0 / n)
        errors.append(np.abs(x - expm(L) @ np.array([1.0, 0.0])).max())
    assert errors[0] / errors[1] == pytest.approx(2.0, rel=0.15)
