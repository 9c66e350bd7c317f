"""Tests of coopctrl.integrators: order, stability limits, stiff accuracy, registry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import expm

from coopctrl.errors import DivergenceError, ScenarioError
from coopctrl.integrators import (
    INTEGRATORS,
    DiagonallyImplicitRungeKutta,
    ImplicitEuler,
    ImplicitMidpoint,
    NewtonConvergenceError,
    get_integrator,
    integrate,
)
from coopctrl.integrators.base import Integrator, spectral_radius

ORDERS = {"euler": 1, "symplectic_euler": 1, "rk4": 4, "implicit_midpoint": 2, "implicit_euler": 1}
IMPLICIT = ("implicit_midpoint", "implicit_euler")


def oscillator(omega: float, zeta: float = 0.0):
    """``ddz = -omega^2 z - 2 zeta omega dz + u`` on n = 2 uncoupled coordinates."""

    def f(t, x, u):
        z, dz = x[:2], x[2:]
        return np.concatenate((dz, -omega * omega * z - 2.0 * zeta * omega * dz + u))

    return f


def exact_oscillator(omega, zeta, x0, u, times):
    """Exact solution through the matrix exponential of the affine system (u constant)."""
    A = np.zeros((5, 5))
    A[0:2, 2:4] = np.eye(2)
    A[2:4, 0:2] = -omega * omega * np.eye(2)
    A[2:4, 2:4] = -2.0 * zeta * omega * np.eye(2)
    A[2:4, 4] = u
    s0 = np.append(x0, 1.0)
    return np.array([(expm(A * t) @ s0)[:4] for t in times])


def test_registry_names_and_orders():
    assert set(INTEGRATORS) == set(ORDERS)
    for name, order in ORDERS.items():
        scheme = get_integrator(name)
        assert scheme.name == name
        assert scheme.order == order
        assert scheme.__doc__ and "stab" in scheme.__doc__.lower()


def test_unknown_name_raises_and_lists_valid_names():
    with pytest.raises(ValueError, match="rk4") as info:
        get_integrator("rk5")
    assert isinstance(info.value, ScenarioError)
    for name in INTEGRATORS:
        assert repr(name) in str(info.value)


def test_unknown_option_raises():
    with pytest.raises(TypeError):
        get_integrator("implicit_midpoint", tolerance=1e-3)


@pytest.mark.parametrize("zeta", [0.0, 0.2], ids=["undamped", "damped"])
@pytest.mark.parametrize("name", list(ORDERS))
def test_error_slope_matches_order(name, zeta):
    omega, T = 2.0, 4.0
    x0 = np.array([1.0, -0.5, 0.3, 0.8])
    u = np.array([0.7, -0.2])
    f = oscillator(omega, zeta)
    steps = [100, 200, 400, 800]
    errors = []
    for n in steps:
        h = T / n
        res = integrate(f, x0, u, 0.0, h, n, name)
        exact = exact_oscillator(omega, zeta, x0, u, res.t)
        errors.append(np.abs(res.x - exact).max())
    slope = np.polyfit(np.log([T / n for n in steps]), np.log(errors), 1)[0]
    assert abs(slope - ORDERS[name]) <= 0.3, (name, slope, errors)


def _grows(name, omega, h, n_steps=4000, factor=10.0):
    """True when the amplitude of an undamped oscillator grows by ``factor`` within n_steps."""
    f = oscillator(omega)
    scheme = get_integrator(name)
    x = np.array([1.0, 0.0, 0.0, omega])  # two phases, unit scaled amplitude
    u = np.zeros(2)
    scale = np.array([omega, omega, 1.0, 1.0])
    a0 = np.abs(x * scale).max()
    for k in range(n_steps):
        x = scheme.step(f, k * h, x, u, h)
        if not np.abs(x * scale).max() <= factor * a0:
            return True
    return False


@pytest.mark.parametrize("name", ["symplectic_euler", "rk4"])
@pytest.mark.parametrize("omega", [1.0, 50.0])
def test_measured_stability_limit_matches_prediction(name, omega):
    predicted = get_integrator(name).predicted_max_step(omega)
    lo, hi = 0.5 * predicted, 1.5 * predicted
    assert not _grows(name, omega, lo) and _grows(name, omega, hi)
    for _ in range(16):
        mid = 0.5 * (lo + hi)
        if _grows(name, omega, mid):
            hi = mid
        else:
            lo = mid
    measured = 0.5 * (lo + hi)
    assert abs(measured / predicted - 1.0) <= 0.05, (measured, predicted)


def test_predicted_limits_values():
    omega = 10.0
    assert get_integrator("euler").predicted_max_step(omega) == 0.0
    assert get_integrator("symplectic_euler").predicted_max_step(omega) == pytest.approx(0.2)
    assert get_integrator("rk4").predicted_max_step(omega) == pytest.approx(2 * math.sqrt(2) / omega)
    assert get_integrator("implicit_midpoint").predicted_max_step(omega) == math.inf
    assert get_integrator("implicit_euler").predicted_max_step(omega) == math.inf
    for name in ORDERS:
        assert get_integrator(name).predicted_max_step(0.0) == math.inf
        with pytest.raises(ValueError, match="omega_max"):
            get_integrator(name).predicted_max_step(-1.0)


@pytest.mark.parametrize("h_omega", [1e-3, 0.1, 1.0, 3.0])
def test_explicit_euler_grows_on_undamped_oscillator(h_omega):
    omega = 5.0
    h = h_omega / omega
    res = integrate(oscillator(omega), [1.0, 0.0, 0.0, 0.0], np.zeros(2), 0.0, h, 200, "euler")
    energy = 0.5 * (res.x[:, 2:] ** 2).sum(axis=1) + 0.5 * omega**2 * (res.x[:, :2] ** 2).sum(axis=1)
    assert np.all(np.diff(energy) > 0.0)
    assert energy[-1] / energy[0] == pytest.approx((1.0 + h_omega**2) ** 200, rel=1e-9)


def test_rk4_real_axis_limit_documented():
    from coopctrl.integrators import RK4_IMAGINARY_AXIS_LIMIT, RK4_REAL_AXIS_LIMIT

    R = lambda z: 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24
    assert abs(R(1j * RK4_IMAGINARY_AXIS_LIMIT)) == pytest.approx(1.0, abs=1e-12)
    assert abs(R(1j * RK4_IMAGINARY_AXIS_LIMIT * 1.001)) > 1.0
    assert R(-RK4_REAL_AXIS_LIMIT) == pytest.approx(1.0, abs=1e-12)
    assert abs(R(-RK4_REAL_AXIS_LIMIT * 1.001)) > 1.0


def _stiff_forced(omega, Omega, amplitude):
    def f(t, x, u):
        return np.array([x[1], -omega * omega * x[0] + omega * omega * amplitude * math.sin(Omega * t)])

    static = amplitude * omega**2 / (omega**2 - Omega**2)
    return f, static


@pytest.mark.parametrize("name", IMPLICIT)
def test_implicit_stiff_oscillator_at_ten_times_rk4_limit(name):
    """Measured relative errors: implicit midpoint 4e-5, implicit Euler 7e-9 (started on the slow
    particular solution, backward Euler's position error settles at ~ h Omega (Omega / omega)^2 / 2
    relative, 3.5e-9: the stiff mode damps its own local errors). Both bounds below are 1e-3."""
    omega, Omega, amplitude = 1e4, 2.0 * math.pi, 1e-3
    f, static = _stiff_forced(omega, Omega, amplitude)
    h = 10.0 * get_integrator("rk4").predicted_max_step(omega)
    n = int(round(2.0 / h))
    x0 = np.array([0.0, static * Omega])  # on the particular solution
    scheme = get_integrator(name)
    res = integrate(f, x0, None, 0.0, h, n, scheme)
    exact = static * np.sin(Omega * res.t)
    assert np.abs(res.x[:, 0] - exact).max() <= 1e-3 * static
    assert abs(np.abs(res.x[:, 0]).max() / static - 1.0) <= 1e-3
    # Stable: the second second is not worse than the first.
    half = n // 2
    err = np.abs(res.x[:, 0] - exact)
    assert err[half:].max() <= 2.0 * err[: half + 1].max() + 1e-12
    # Simplified Newton: one Jacobian for the whole (linear) run.
    assert scheme.jacobian_evaluations == 1
    # The explicit schemes blow up at this step.
    with pytest.raises(DivergenceError):
        integrate(f, x0, None, 0.0, h, n, "rk4")


class _SDIRK2(DiagonallyImplicitRungeKutta):
    """Two-stage L-stable SDIRK (Alexander 1977), gamma = 1 - 1/sqrt(2): a test of the multi-stage path
    of the shared machinery (not registered: see :class:`ImplicitEuler`). Stability: R(z) =
    (1 + (1 - 2 gamma) z) / (1 - gamma z)^2."""

    name = "sdirk2"
    order = 2
    tableau = ((1.0 - 1.0 / math.sqrt(2.0),), (1.0 / math.sqrt(2.0), 1.0 - 1.0 / math.sqrt(2.0)))
    weights = (1.0 / math.sqrt(2.0), 1.0 - 1.0 / math.sqrt(2.0))
    stability_numerator = (1.0, math.sqrt(2.0) - 1.0)


DIRK = [ImplicitMidpoint, ImplicitEuler, _SDIRK2]


@pytest.mark.parametrize("cls", DIRK, ids=lambda c: c.name)
def test_stability_function_is_the_tableau_and_the_step(cls):
    """The documented ``R(z) = N(z) / (1 - gamma z)^s`` equals ``1 + z b^T (I - z A)^-1 1`` of the tableau
    (seeded complex z; to 1e-12 relative, round-off of a 2x2 solve), and the matrix of one actual step on a
    damped oscillator ``dx/dt = L x`` is ``R(h L)`` (to 1e-10: the Newton tolerance is 1e-12 relative to
    the state, the finite-difference Jacobian only slows the convergence to it)."""
    scheme = cls()
    A = np.zeros((len(cls.tableau),) * 2)
    for i, row in enumerate(cls.tableau):
        A[i, : i + 1] = row
    b = np.array(cls.weights)
    ones = np.ones(len(b))
    rng = np.random.default_rng(3)
    for z in rng.normal(size=8) * 10 + 1j * rng.normal(size=8) * 10:
        direct = 1.0 + z * b @ np.linalg.solve(np.eye(len(b)) - z * A, ones)
        assert scheme.stability_function(z) == pytest.approx(direct, rel=1e-12)
    L = np.array([[0.0, 1.0], [-400.0, -4.0]])  # omega = 20 rad/s, zeta = 0.1
    h = 0.3  # h omega = 6: far beyond every explicit limit
    w, V = np.linalg.eig(L)
    expected = (V @ np.diag(scheme.stability_function(h * w)) @ np.linalg.inv(V)).real
    np.testing.assert_allclose(Integrator.one_step_matrix(scheme, L, h), expected, rtol=0, atol=1e-10)


def test_sdirk_machinery_has_order_two_with_two_stages():
    """The multi-stage path (stage predictors, one Newton matrix for both stages) on the undamped forced
    oscillator of test_error_slope_matches_order: slope 2 within 0.3 as there."""
    omega, T = 2.0, 4.0
    x0 = np.array([1.0, -0.5, 0.3, 0.8])
    u = np.array([0.7, -0.2])
    errors = []
    for n in (100, 200, 400, 800):
        res = integrate(oscillator(omega), x0, u, 0.0, T / n, n, _SDIRK2())
        errors.append(np.abs(res.x - exact_oscillator(omega, 0.0, x0, u, res.t)).max())
    slope = np.polyfit(np.log([T / n for n in (100, 200, 400, 800)]), np.log(errors), 1)[0]
    assert abs(slope - 2) <= 0.3, (slope, errors)


def test_tableau_is_checked():
    with pytest.raises(TypeError, match="lower triangular"):
        type("Bad", (DiagonallyImplicitRungeKutta,), {"tableau": ((0.5,), (0.5, 0.3)), "weights": (0.5, 0.5)})


def test_implicit_euler_is_l_stable():
    """``R(z) = 1 / (1 - z)``: ``|R(i y)| = 1 / sqrt(1 + y^2)`` and ``|R(z)| -> 0`` as ``|z| -> inf`` in every
    direction of the left half-plane (L-stable); implicit midpoint's ``|R|`` stays 1 (A- but not L-stable)."""
    be, mid = get_integrator("implicit_euler"), get_integrator("implicit_midpoint")
    y = np.logspace(-3, 8, 45)
    np.testing.assert_allclose(np.abs(be.stability_function(1j * y)), 1.0 / np.sqrt(1.0 + y * y), rtol=1e-14)
    for angle in np.linspace(0.5 * np.pi, np.pi, 7):  # the imaginary axis to the negative real axis
        z = 1e8 * np.exp(1j * angle)
        assert abs(be.stability_function(z)) <= 1.01e-8
        assert abs(mid.stability_function(z)) == pytest.approx(1.0, abs=1e-7)


def test_implicit_euler_damps_a_stiff_decoupled_mode_in_one_step():
    """A slow (1 rad/s) and a stiff (1e5 rad/s) undamped oscillator, decoupled, one step of 10 ms
    (``h omega`` = 0.01 and 1000). In the scaled coordinates ``(z, dz / omega)`` a mode's one-step map is
    ``|R(i h omega)|`` times a rotation, so each amplitude is multiplied by exactly that: backward Euler
    leaves the stiff mode 1e-3 of its amplitude and takes ``(h omega)^2 / 2 = 5e-5`` off the slow one;
    implicit midpoint keeps both. Tolerance 1e-6 relative: the Newton tolerance is 1e-12 relative to the
    largest state entry (the stiff velocity, ~ 100 m/s after the step), 1e-10 absolute."""
    omegas = np.array([1.0, 1e5])

    def f(t, x, u):
        return np.concatenate((x[2:], -omegas**2 * x[:2]))

    def amplitudes(x):
        return np.hypot(x[:2], x[2:] / omegas)

    h = 0.01
    x0 = np.array([1.0, 1.0, 0.0, 0.0])
    be = amplitudes(get_integrator("implicit_euler").step(f, 0.0, x0, None, h))
    np.testing.assert_allclose(be, 1.0 / np.sqrt(1.0 + (h * omegas) ** 2), rtol=1e-6)
    assert be[1] <= 1.001e-3 and 1.0 - be[0] == pytest.approx(0.5 * (h * omegas[0]) ** 2, rel=1e-3)
    mid = amplitudes(get_integrator("implicit_midpoint").step(f, 0.0, x0, None, h))
    np.testing.assert_allclose(mid, 1.0, rtol=1e-6)


@pytest.mark.parametrize("zeta", [0.0, 0.05, 1.0, 3.0])
def test_implicit_euler_is_unconditionally_stable(zeta):
    """The spectral radius of the scheme's own one-step matrix (its step applied to the identity) on an
    oscillator stays <= 1 from ``h omega`` = 1e-2 to 1e6 (1e-12: round-off of a 2x2 eigenvalue problem);
    undamped, it is ``1 / sqrt(1 + (h omega)^2)`` < 1: the scheme dissipates at every step."""
    omega = 50.0
    L = np.array([[0.0, 1.0], [-omega * omega, -2.0 * zeta * omega]])
    scheme = get_integrator("implicit_euler")
    for y in np.logspace(-2, 6, 33):
        rho = spectral_radius(Integrator.one_step_matrix(scheme, L, y / omega))
        assert rho <= 1.0 + 1e-12, (y, rho)
        if zeta == 0.0:
            assert rho == pytest.approx(1.0 / math.sqrt(1.0 + y * y), rel=1e-9)


def test_implicit_euler_energy_decays_at_the_predicted_rate():
    """Undamped oscillator, ``h omega = 0.3``, 200 steps: the energy (quadratic, a norm in which the map
    is ``R`` times a rotation) falls by exactly ``1 / (1 + (h omega)^2)`` per step, monotonically: the
    numerical damping of the docstring (to 1e-9 relative per step: the Newton tolerance)."""
    omega, h = 3.0, 0.1
    res = integrate(oscillator(omega), [1.0, -0.4, 0.2, 2.0], np.zeros(2), 0.0, h, 200, "implicit_euler")
    energy = 0.5 * (res.x[:, 2:] ** 2).sum(axis=1) + 0.5 * omega**2 * (res.x[:, :2] ** 2).sum(axis=1)
    np.testing.assert_allclose(energy[1:] / energy[:-1], 1.0 / (1.0 + (h * omega) ** 2), rtol=1e-9)


def test_newton_failure_names_the_scheme():
    """``dv = v^2 + 1`` from rest has no real backward-Euler solution at h = 10 (``10 v^2 - v + 10 = 0``)."""

    def f(t, x, u):
        return np.array([x[1], x[1] * x[1] + 1.0])

    with pytest.raises(NewtonConvergenceError, match="^implicit_euler: Newton did not converge") as info:
        get_integrator("implicit_euler").step(f, 0.0, np.array([0.0, 0.0]), None, 10.0)
    assert info.value.scheme == "implicit_euler" and info.value.suggested_step == 5.0


def test_implicit_midpoint_conserves_quadratic_energy():
    omega = 3.0
    f = oscillator(omega)
    res = integrate(f, [1.0, -0.4, 0.2, 2.0], np.zeros(2), 0.0, 0.1, 2000, "implicit_midpoint")
    energy = 0.5 * (res.x[:, 2:] ** 2).sum(axis=1) + 0.5 * omega**2 * (res.x[:, :2] ** 2).sum(axis=1)
    assert np.abs(energy / energy[0] - 1.0).max() <= 1e-10


def test_implicit_midpoint_on_a_bound_method_matches_a_function():
    """A plant object's ``rhs`` steps like a plain function of the same system (the Jacobian is by
    finite differences for both; an analytic ``jac`` is not used): positions within 1e-12 m over 50
    steps (the Newton tolerance is 1e-12 relative to a unit state)."""
    omega = 7.0

    class Plant:
        def rhs(self, t, x, u):
            return np.array([x[1], -omega**2 * x[0] + u])

    fd = integrate(oscillator(omega), [1.0, 0.0, 0.0, 0.0], np.zeros(2), 0.0, 0.05, 50, "implicit_midpoint")
    res = integrate(Plant().rhs, [1.0, 0.0], 0.0, 0.0, 0.05, 50, "implicit_midpoint")
    np.testing.assert_allclose(res.x[:, 0], fd.x[:, 0], rtol=0, atol=1e-12)


def test_implicit_midpoint_nonlinear_matches_reference():
    """Pendulum with large steps against a fine RK4 reference (order 2 accuracy)."""

    def f(t, x, u):
        return np.array([x[1], -9.81 * math.sin(x[0]) - 0.1 * x[1] + u])

    x0 = np.array([2.5, 0.0])
    ref = integrate(f, x0, 0.3, 0.0, 1e-4, 20000, "rk4").x[-1]
    errors = []
    for n in (100, 200, 400):
        errors.append(np.abs(integrate(f, x0, 0.3, 0.0, 2.0 / n, n, "implicit_midpoint").x[-1] - ref).max())
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.15)
    assert errors[1] / errors[2] == pytest.approx(4.0, rel=0.15)


def test_implicit_midpoint_newton_failure_raises():
    """``dv = v^2 + 1`` has no real midpoint solution for a large step."""

    def f(t, x, u):
        return np.array([x[1], x[1] * x[1] + 1.0])

    scheme = ImplicitMidpoint(max_iterations=30)
    with pytest.raises(NewtonConvergenceError) as info:
        scheme.step(f, 0.0, np.array([0.0, 0.0]), None, 10.0)
    err = info.value
    assert isinstance(err, ArithmeticError) and isinstance(err, DivergenceError)
    assert err.iterations <= 30 and err.step == 10.0
    assert "reduce the step" in str(err)


def test_implicit_midpoint_non_finite_rhs_raises():
    def f(t, x, u):
        return np.array([x[1], math.nan])

    with pytest.raises(NewtonConvergenceError):
        ImplicitMidpoint().step(f, 0.0, np.array([0.0, 0.0]), None, 0.1)


@pytest.mark.parametrize("name", list(ORDERS))
def test_step_does_not_modify_input_and_returns_new_array(name):
    f = oscillator(2.0, 0.1)
    x = np.array([1.0, 2.0, 3.0, 4.0])
    keep = x.copy()
    x1 = get_integrator(name).step(f, 0.0, x, np.zeros(2), 0.01)
    np.testing.assert_array_equal(x, keep)
    assert x1 is not x and x1.shape == x.shape


def test_symplectic_euler_uses_new_velocity():
    f = oscillator(1.0)
    x = np.array([1.0, 0.0, 0.0, 0.0])
    x1 = get_integrator("symplectic_euler").step(f, 0.0, x, np.zeros(2), 0.1)
    np.testing.assert_allclose(x1, [1.0 - 0.01, 0.0, -0.1, 0.0])


def test_integrate_validates_and_detects_divergence():
    f = oscillator(1.0)
    with pytest.raises(ValueError, match="h"):
        integrate(f, [1.0, 0, 0, 0], np.zeros(2), 0.0, -0.1, 10, "rk4")
    with pytest.raises(ValueError, match="x0"):
        integrate(f, [1.0, 0, 0], np.zeros(2), 0.0, 0.1, 10, "rk4")
    with pytest.raises(DivergenceError):
        integrate(f, [1.0, 0, 0, 0], np.zeros(2), 0.0, 1.0, 5000, "euler")


def test_integrate_samples_callable_input():
    """A callable input is held over each step (zero-order hold)."""

    def f(t, x, u):
        return np.array([x[1], u])

    res = integrate(f, [0.0, 0.0], lambda t: 1.0 if t < 0.5 else 0.0, 0.0, 0.25, 4, "euler")
    np.testing.assert_allclose(res.x[:, 1], [0.0, 0.25, 0.5, 0.5, 0.5])


def test_implicit_midpoint_converges_from_zero_state_with_large_motion():
    """The tolerance scales with the new state too, not only with a zero initial state."""

    def f(t, x, u):
        return np.array([x[1], u - 0.5 * x[1] * abs(x[1])])

    x1 = ImplicitMidpoint().step(f, 0.0, np.zeros(2), 1e6, 0.01)
    assert np.all(np.isfinite(x1)) and x1[1] > 0.0
    # Residual of the midpoint equation at the tight tolerance.
    k = x1 / 0.01
    np.testing.assert_allclose(k, f(0.005, 0.5 * x1, 1e6), rtol=1e-11)


@pytest.mark.parametrize("name, setting, value", [("implicit_euler", "rtol", 1e-6), ("rk45", "atol", 1e-3),
                                                  ("trbdf2", "newton_tol", 0.1)])
def test_settings_are_frozen_configuration(name, setting, value):
    """A built-in scheme's settings are set once by its constructor: changing one raises, naming the
    setting and how to get another (a new scheme); the scheme keeps its value."""
    scheme = get_integrator(name)
    before = getattr(scheme, setting)
    with pytest.raises(AttributeError, match=f"{setting} is a frozen setting.*get_integrator"):
        setattr(scheme, setting, value)
    assert getattr(scheme, setting) == before
    assert getattr(get_integrator(name, **{setting: value}), setting) == value
