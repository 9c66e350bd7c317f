"""coopctrl/core's error-controlled schemes (adaptive_schemes.h): ``coopctrl._core.adaptive_advance`` on a planar
plant's PlantArgs against ``adaptive_advance_f`` on the plant's own ``rhs`` as a Python f (the plant's Python path,
an independent evaluation of the same right-hand side: the same bits, plan and statistics after every period), for
rk23 and rk45 under each step controller and trbdf2, over several control periods from the golden records' states
of planar shipped scenes; the stop below min_step, TR-BDF2's Newton iteration that does not converge, a plant
failure and a Python f that is NaN beyond a wall take their documented paths; the first step against its numpy
statement (scipy's select_initial_step); the packed arrays read by name.

The schemes' arithmetic is checked against scipy (step for step) and DOP853 in tests/test_integrators_adaptive_plans.py.
The core was checked bit for bit against the numba advances it replaced when it was ported; the golden records lock
a run's numbers since."""

from __future__ import annotations

import numpy as np
import pytest

import _golden
import coopctrl
import coopctrl.integrators.adaptive_plans as adaptive
from coopctrl import _core
from coopctrl.integrators import get_integrator
from coopctrl.integrators.compiled import STEP_OK, STEP_PLANT_ERROR, STEP_TOO_SMALL
from coopctrl.wiring import closed_loop
from plants import _core as plants_core

SCENES = ["planar_two_arm_lift", "fidelity_planar", "gripping_immobile_object"]

#: (scheme, step controller): each pair under each controller; TR-BDF2 under its own and fixed steps.
SCHEMES = [("rk23", "pi"), ("rk23", "elementary"), ("rk23", "fixed"), ("rk45", "pi"), ("rk45", "elementary"),
           ("rk45", "fixed"), ("trbdf2", "pi"), ("trbdf2", "fixed")]

PERIODS = 6


class _Scene:
    """A planar shipped scene's plant, its control period, and its golden record's states and torques."""

    def __init__(self, name: str):
        loop = closed_loop(coopctrl.load_scenario(name))
        self.plant = loop.plant
        self.P = self.plant.plant_args
        assert self.P.bases.ndim == 2, f"{name} is spatial"
        self.T = float(loop.T)
        with np.load(_golden.path_of(name)) as record:  # the run's start and a later sample
            picks = [0, len(record["x"]) // 2]
            self.states = [np.array(record["x"][i]) for i in picks]
            self.torques = [np.array(record["tau"][i]) for i in picks]


_SCENES: dict[str, _Scene] = {}


def _scene(name: str) -> _Scene:
    if name not in _SCENES:
        _SCENES[name] = _Scene(name)
    return _SCENES[name]


def _run_both(scene: _Scene, integrator, controller, x0, tau, periods=PERIODS, fixed_step=0.0):
    """``periods`` periods from ``x0`` by the core on the PlantArgs and by the core on the plant's ``rhs`` as a Python
    ``f``, everything compared after each; the codes and the plan."""
    nx = x0.shape[0]
    plans = [adaptive.adaptive_plan(integrator, nx, scene.T, periods, controller=controller, fixed_step=fixed_step)
             for _ in range(2)]
    states = [x0.copy(), x0.copy()]
    status = np.zeros(2, np.int64)
    fails = [np.zeros(nx), np.zeros(nx)]
    reports = [_core.StopReport(), _core.StopReport()]
    plant = scene.plant
    codes = []
    for k in range(periods):
        t = k * scene.T
        want = _core.adaptive_advance(plans[0], states[0], tau, scene.P, status, t, fails[0], reports[0])
        got = _core.adaptive_advance_f(plans[1], lambda t, x, u: plant.rhs(t, x, u), states[1], tau, t, fails[1],
                                       reports[1])
        assert got == want, f"period {k}"
        np.testing.assert_array_equal(states[1], states[0], err_msg=f"x, period {k}")
        np.testing.assert_array_equal(fails[1], fails[0], err_msg=f"x_fail, period {k}")
        assert reports[1] == reports[0], f"report, period {k}: {reports[1]} != {reports[0]}"
        for field, a, b in zip(plans[0]._fields, plans[1], plans[0]):
            np.testing.assert_array_equal(a, b, err_msg=f"plan.{field}, period {k}")
        codes.append(int(want))
        if want != STEP_OK:
            break
    return codes, plans[0], np.array(reports[0].value)


@pytest.mark.parametrize("name", SCENES)
@pytest.mark.parametrize("scheme,controller", SCHEMES)
def test_a_run_of_periods_on_the_plant_args_is_the_python_f_path(name, scheme, controller):
    scene = _scene(name)
    rng = np.random.default_rng(len(name) + len(scheme))
    for x0, tau in zip(scene.states, scene.torques):
        x = x0 + rng.normal(scale=1e-3, size=x0.shape)  # every spring and damper works
        fixed_step = scene.T / 4.0 if controller == "fixed" else 0.0
        codes, plan, _ = _run_both(scene, get_integrator(scheme), controller, x, tau, fixed_step=fixed_step)
        assert codes == [STEP_OK] * PERIODS
        assert np.all(plan.stats[:, adaptive.STAT_ACCEPTED] >= 1)


@pytest.mark.parametrize("scheme,controller", [case for case in SCHEMES if case[1] != "fixed"])
def test_the_step_controllers_reject_and_recover(scheme, controller):
    """A stiff grasp over ten periods: hundreds of controlled steps, rejected ones among them."""
    scene = _scene("stiff_grasp_extreme")
    x = scene.states[1] + np.random.default_rng(11).normal(scale=1e-3, size=scene.states[1].shape)
    codes, plan, _ = _run_both(scene, get_integrator(scheme), controller, x, scene.torques[1], periods=10)
    assert codes == [STEP_OK] * 10
    assert plan.stats[:, adaptive.STAT_REJECTED].sum() > 0
    assert plan.stats[:, adaptive.STAT_ACCEPTED].sum() > 100


@pytest.mark.parametrize("scheme", ["rk23", "rk45", "trbdf2"])
def test_a_step_below_min_step_stops(scheme):
    """A tight tolerance with a large min_step: the controller's step falls below it within the first periods;
    the report's ``value`` = (that step, the time it was tried at, within the period)."""
    scene = _scene("planar_two_arm_lift")
    integrator = get_integrator(scheme, rtol=1e-12, atol=1e-14, min_step=scene.T / 8.0)
    x = scene.states[1] + np.random.default_rng(3).normal(scale=1e-2, size=scene.states[1].shape)
    codes, plan, value = _run_both(scene, integrator, None, x, scene.torques[1])
    assert codes[-1] == STEP_TOO_SMALL
    k = len(codes) - 1
    assert 0.0 < value[0] < scene.T / 8.0
    assert k * scene.T <= value[1] < (k + 1) * scene.T


@pytest.mark.parametrize("name", SCENES)
def test_trbdf2_whose_newton_iteration_does_not_converge(name):
    """One Newton iteration per stage: a stage that does not converge takes a Jacobian at x, then quarters the
    remaining steps (counted as rejected). At Newton's own tolerance the steps converge once small enough (hundreds
    of Jacobians over three periods); at a tolerance a single iteration cannot meet, they fall below min_step."""
    scene = _scene(name)
    x = scene.states[1] + np.random.default_rng(5).normal(scale=1e-3, size=scene.states[1].shape)
    integrator = get_integrator("trbdf2", max_iterations=1, min_step=1e-7)
    codes, plan, _ = _run_both(scene, integrator, None, x, scene.torques[1], periods=3)
    assert codes == [STEP_OK] * 3
    assert plan.stats[:, adaptive.STAT_REJECTED].sum() > 100
    assert plan.memo[adaptive.M_JACOBIANS] > 100
    integrator = get_integrator("trbdf2", max_iterations=1, newton_tol=1e-6, min_step=1e-7)
    codes, plan, _ = _run_both(scene, integrator, None, x, scene.torques[1], periods=3)
    assert codes == [STEP_TOO_SMALL]
    assert plan.stats[0, adaptive.STAT_REJECTED] > 0


def _pendulum_to_a_wall(t, x, u):
    """A driven pendulum not defined beyond the angle 1 rad (NaN there)."""
    if x[0] > 1.0:
        return np.array([np.nan, np.nan])
    return np.array([x[1], -9.81 * np.sin(x[0]) + u[0]])


@pytest.mark.parametrize("scheme,controller", [("rk23", "pi"), ("rk45", "pi"), ("rk45", "elementary"),
                                               ("trbdf2", "pi")])
def test_a_python_f_that_is_nan_beyond_a_wall_stops_below_min_step(scheme, controller):
    """Swinging up to the wall: the steps into it are rejected on their NaN error until one is below min_step; the
    state stays on the defined side, and ``x_fail`` is the state the too small step was tried from."""
    T = 0.05
    integrator = get_integrator(scheme, min_step=1e-9)
    plan = adaptive.adaptive_plan(integrator, 2, T, 10, controller=controller)
    x = np.array([0.5, 3.0])
    tau = np.array([0.5])
    report, x_fail = _core.StopReport(), np.zeros(2)
    codes = []
    for k in range(10):
        code = _core.adaptive_advance_f(plan, _pendulum_to_a_wall, x, tau, k * T, x_fail, report)
        codes.append(int(code))
        if code != STEP_OK:
            break
    assert codes[-1] == STEP_TOO_SMALL and len(codes) > 2
    assert plan.stats[len(codes) - 1, adaptive.STAT_REJECTED] > 0
    assert report.value[0] < 1e-9  # the step [s]
    np.testing.assert_array_equal(x_fail, x)
    assert np.all(np.isfinite(x)) and x[0] <= 1.0


@pytest.mark.parametrize("scheme", ["rk45", "trbdf2"])
def test_a_plant_failure_is_reported(scheme):
    """The object's centre on a contact (a central spring of rest length > 0 at zero length): the plant fails at
    the period's first evaluation (its status set, ``x_fail`` the state), as the plant's own ``rhs`` does."""
    scene = _scene("central_spring_buckling")
    x = scene.states[0].copy()
    nz = x.shape[0] // 2
    x[nz - 3:nz - 1] = plants_core.planar_control_terms(x, scene.P)["Y"][1, :2]
    plan = adaptive.adaptive_plan(get_integrator(scheme), x.shape[0], scene.T, 1)
    status, x_fail = np.zeros(2, np.int64), np.zeros_like(x)
    code = _core.adaptive_advance(plan, x.copy(), scene.torques[0], scene.P, status, 0.0, x_fail, _core.StopReport())
    assert code == STEP_PLANT_ERROR and status[0] != 0
    np.testing.assert_array_equal(x_fail, x)
    with pytest.raises(Exception):
        scene.plant.rhs(0.0, x, scene.torques[0])


@pytest.mark.parametrize("name", SCENES)
def _initial_step(x, f0, f1_of, atol, rtol, order, interval):
    """The first step (the module docstring of coopctrl.integrators.adaptive_plans, scipy's select_initial_step) in
    numpy; ``f1_of(y1)`` the slope after the Euler step."""
    scale = atol + np.abs(x) * rtol
    d0, d1 = np.sqrt(np.mean((x / scale) ** 2)), np.sqrt(np.mean((f0 / scale) ** 2))
    h0 = min(1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1, interval)
    y1 = x + h0 * f0
    d2 = np.sqrt(np.mean(((f1_of(y1) - f0) / scale) ** 2)) / h0
    h1 = max(1e-6, h0 * 1e-3) if d1 <= 1e-15 and d2 <= 1e-15 else (0.01 / max(d1, d2)) ** (1.0 / (order + 1.0))
    return min(100.0 * h0, h1, interval), y1


@pytest.mark.parametrize("name", SCENES)
def test_the_initial_step_is_scipys_rule(name):
    """The core's first step and its Euler state against the numpy statement (1e-12 relative: sums in another
    order), at the golden records' states."""
    scene = _scene(name)
    integrator = get_integrator("rk23")
    for x, tau in zip(scene.states, scene.torques):
        nx = x.shape[0]
        atol = integrator.tolerances(nx // 2, scene.T)
        f0 = scene.plant.rhs(0.0, x, tau)
        for order in (2.0, 4.0):
            y1, f1, status = np.zeros(nx), np.zeros(nx), np.zeros(2, np.int64)
            got = _core.adaptive_initial_step(x, f0, y1, f1, atol, 1e-6, order, scene.T, tau, scene.P, status)
            want, y1_want = _initial_step(x, f0, lambda y: scene.plant.rhs(0.0, y, tau), atol, 1e-6, order, scene.T)
            assert got == pytest.approx(want, rel=1e-12)
            np.testing.assert_array_equal(y1, y1_want)
            np.testing.assert_array_equal(f1, scene.plant.rhs(0.0, y1, tau))
            assert status[0] == 0


def test_the_packed_arrays_are_read_where_the_python_plans_write_them():
    settings = {"rtol": adaptive.S_RTOL, "min_step": adaptive.S_MIN_STEP, "safety": adaptive.S_SAFETY,
                "min_factor": adaptive.S_MIN_FACTOR, "max_factor": adaptive.S_MAX_FACTOR,
                "error_order": adaptive.S_ERROR_ORDER, "controller": adaptive.S_CONTROLLER,
                "period": adaptive.S_PERIOD, "newton_tol": adaptive.S_NEWTON_TOL,
                "max_iterations": adaptive.S_MAX_ITER}
    memo = {"carry": adaptive.M_CARRY, "error_prev": adaptive.M_ERR_PREV, "fixed_step": adaptive.M_FIXED,
            "parts": adaptive.M_PARTS, "gh": adaptive.M_GH, "have_jacobian": adaptive.M_HAVE_J,
            "jacobians": adaptive.M_JACOBIANS, "fresh": adaptive.M_FRESH}
    statistics = {"accepted": adaptive.STAT_ACCEPTED, "rejected": adaptive.STAT_REJECTED,
                  "rhs_evaluations": adaptive.STAT_RHS, "min_step": adaptive.STAT_MIN_STEP}
    assert dict(_core.ADAPTIVE_SETTINGS) == settings
    assert dict(_core.ADAPTIVE_MEMO) == memo
    assert dict(_core.STEP_STATISTICS) == statistics
    assert (adaptive.CONTROLLER_PI, adaptive.CONTROLLER_ELEMENTARY, adaptive.CONTROLLER_FIXED) == (0, 1, 2)


def test_bad_arguments_are_named():
    scene = _scene("planar_two_arm_lift")
    x, tau = scene.states[0].copy(), scene.torques[0]
    nx = x.shape[0]
    plan = adaptive.adaptive_plan(get_integrator("rk23"), nx, scene.T, 1)
    args = (np.zeros(2, np.int64), 0.0, np.zeros(nx), _core.StopReport())
    with pytest.raises(ValueError, match=r"plan\.K: expected"):
        _core.adaptive_advance(plan._replace(K=np.zeros((3, nx))), x, tau, scene.P, *args)
    with pytest.raises(ValueError, match=r"^x: expected length"):
        _core.adaptive_advance(plan, np.zeros(nx + 2), tau, scene.P, *args)
    with pytest.raises(ValueError, match=r"^tau: expected length"):
        _core.adaptive_advance(plan, x, np.zeros(tau.shape[0] + 1), scene.P, *args)
    with pytest.raises(TypeError, match="EmbeddedPlan or a TRBDF2Plan"):
        _core.adaptive_advance((1, 2), x, tau, scene.P, *args)


def test_a_python_exception_in_f_reaches_the_caller():
    def broken(t, x, u):
        raise ZeroDivisionError("f failed")

    plan = adaptive.adaptive_plan(get_integrator("rk45"), 2, 0.01, 1)
    with pytest.raises(ZeroDivisionError, match="f failed"):
        _core.adaptive_advance_f(plan, broken, np.zeros(2), np.zeros(1), 0.0, np.zeros(2), _core.StopReport())


def test_a_python_f_gets_the_stage_times():
    """dx = (1, 0): x_0 is the time. Fixed rk45 steps of 0.25 s over [0.5, 1.0] s (exact in binary): f is called at
    the period's start, then at each step's stage times t + c_i h and its end."""
    seen = []

    def clock(t, x, u):
        seen.append(t)
        return np.array([1.0, 0.0])

    plan = adaptive.adaptive_plan(get_integrator("rk45"), 2, 0.5, 2, controller="fixed", fixed_step=0.25)
    x = np.array([0.5, 0.0])
    code = _core.adaptive_advance_f(plan, clock, x, None, 0.5, np.zeros(2), _core.StopReport())
    assert code == STEP_OK
    C = get_integrator("rk45").C
    want = [0.5] + [t0 + c * 0.25 for t0 in (0.5, 0.75) for c in (*C[1:], 1.0)]
    np.testing.assert_array_equal(seen, want)
    np.testing.assert_allclose(x, [1.0, 0.0], rtol=0, atol=1e-15)
