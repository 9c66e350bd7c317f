"""Error-controlled integration in the compiled loop (coopctrl/core/adaptive_schemes.h on the plans of
:mod:`coopctrl.integrators.adaptive_plans`, stepping the plant in the core as the loop's tick does,
``_core.plant_advance``):
``rk23``, ``rk45`` and ``trbdf2`` against scipy's ``solve_ivp`` (step for step), their orders against DOP853, the
global error's proportionality to ``rtol``, the step statistics, and the stop below ``min_step``."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import RK23, RK45, solve_ivp

import coopctrl
from coopctrl.errors import ScenarioError
from coopctrl.integrators import BogackiShampine, DormandPrince, get_integrator
import coopctrl.integrators.adaptive_plans as adaptive
import coopctrl.integrators.compiled as integrate
from coopctrl import _core
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"


class _Plant:
    """A scene's plant and a seeded state away from equilibrium (every spring and damper works):
    ``x0 + 1e-3 N(0, 1)`` and torques ``0.1 N(0, 1)`` N m, held (seeded generator)."""

    def __init__(self, name: str, seed: int = 7):
        scene = coopctrl.load_scenario(SCENARIOS / f"{name}.toml")
        self.plant = plant = closed_loop(scene).plant
        rng = np.random.default_rng(seed)
        x0 = build.initial_state(scene)
        self.x = x0 + 1e-3 * rng.standard_normal(x0.shape)
        self.tau = 0.1 * rng.standard_normal(plant.input_size)
        self.P = plant.plant_args
        self.nz = plant.nz

    def f(self, t, y):
        return self.plant.rhs(t, y, self.tau)

    def advance(self, integrator, period: float, controller: str | None = None, fixed_step: float = 0.0):
        """One period by the compiled scheme: ``(code, x, rhs evaluations, stats row)``."""
        plan = adaptive.adaptive_plan(integrator, self.x.size, period, 1, controller=controller, fixed_step=fixed_step)
        status, report = np.zeros(2, np.int64), _core.StopReport()
        x, x_fail = self.x.copy(), self.x.copy()
        code = _core.plant_advance(plan, x, self.tau, self.P, status, 0.0, np.array([period]), x_fail, report)
        return code, x, report.rhs_evaluations, plan.stats[0].copy()


@pytest.fixture(scope="module")
def planar():
    return _Plant("planar_two_arm_lift")


@pytest.fixture(scope="module")
def spatial():
    return _Plant("spatial_two_puma_carry")


@pytest.fixture(scope="module")
def stiff():
    return _Plant("stiff_grasp_extreme")


def test_tableaux_are_scipys():
    """The pairs' coefficients are scipy's ``RK23``/``RK45`` (public class attributes), to the last bit
    but one (ours are written as fractions)."""
    for ours, theirs in ((BogackiShampine, RK23), (DormandPrince, RK45)):
        for name in ("A", "B", "C", "E"):
            mine, scipys = np.array(getattr(ours, name)), np.asarray(getattr(theirs, name))
            if name == "A":  # scipy keeps the strictly lower triangle's columns only
                assert not np.any(mine[:, scipys.shape[1]:])
                mine = mine[:, :scipys.shape[1]]
            np.testing.assert_allclose(mine, scipys, rtol=0, atol=1e-15)
        assert ours.error_order == theirs.error_estimator_order
        assert ours.order == theirs.order


@pytest.mark.parametrize("scene", ["planar", "spatial"])
@pytest.mark.parametrize("name,method", [("rk23", "RK23"), ("rk45", "RK45")])
def test_a_period_matches_scipy_step_for_step(scene, name, method, request):
    """With scipy's elementary controller, a frozen-torque period of 20 ms takes the same accepted and
    rejected steps as ``solve_ivp``: the same number of steps and of right-hand-side evaluations (each
    rejection costs a step's stages, so equal counts over ~20 to 100 steps mean the same sequence), and
    the same end state to rounding: the formulas are the same, only the order of the sums differs
    (1e-16 relative per operation, over <= 300 evaluations: 1e-10 is far above it and far below any
    step's own error, 1e-7)."""
    p = request.getfixturevalue(scene)
    T = 0.02
    integ = get_integrator(name, rtol=1e-6, atol=1e-8, atol_velocity=1e-6, controller="elementary")
    code, x, evals, stats = p.advance(integ, T)
    sol = solve_ivp(p.f, (0.0, T), p.x, method=method, rtol=1e-6, atol=integ.tolerances(p.nz, T))
    assert code == integrate.STEP_OK and sol.status == 0
    assert int(stats[adaptive.STAT_ACCEPTED]) == len(sol.t) - 1
    assert evals == sol.nfev == int(stats[adaptive.STAT_RHS])
    assert len(sol.t) - 1 >= 10  # the comparison covers many controlled steps, not one
    np.testing.assert_allclose(x, sol.y[:, -1], rtol=0, atol=1e-10)
    # the public step over the period on the plant's rhs is that compiled period, bit for bit
    same = get_integrator(name, rtol=1e-6, atol=1e-8, atol_velocity=1e-6, controller="elementary")
    np.testing.assert_array_equal(same.step(p.plant.rhs, 0.0, p.x, p.tau, T), x)


@pytest.mark.parametrize("name,order", [("rk23", 3), ("rk45", 5), ("trbdf2", 2)])
def test_orders_against_dop853(planar, name, order):
    """Fixed steps ``h = T/16 .. T/128`` over T = 50 ms on the plant alone: the positions' error
    against DOP853 at rtol 1e-12 falls as ``h^order`` (fitted slope within 0.2). The reference's own
    error (<= 1e-12 relative) is below the smallest error fitted (~1e-10)."""
    T = 0.05
    ref = solve_ivp(planar.f, (0.0, T), planar.x, method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
    hs = [T / n for n in (16, 32, 64, 128)] if order < 5 else [T / n for n in (8, 16, 32, 64)]
    errors = []
    for h in hs:
        code, x, _, stats = planar.advance(get_integrator(name), T, controller="fixed", fixed_step=h)
        assert code == integrate.STEP_OK and stats[adaptive.STAT_REJECTED] == 0
        errors.append(np.max(np.abs(x[:planar.nz] - ref[:planar.nz])))
    slope = np.polyfit(np.log(hs), np.log(errors), 1)[0]
    assert abs(slope - order) <= 0.2, (errors, slope)


#: Tolerances of the proportionality test.
RTOLS = (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9)


@pytest.mark.parametrize("scene", ["planar", "spatial", "stiff"])
@pytest.mark.parametrize("name", ["rk23", "rk45", "trbdf2"])
def test_global_error_follows_rtol(scene, name, request):
    """The global error of the positions after 50 ms (plant alone, torques held, PI controller, atol =
    rtol / 100) against DOP853 at rtol 1e-13 is proportional to ``rtol`` over 1e-3 .. 1e-9 within a factor
    10: ``max / min`` of ``error / rtol`` <= 10 over the seven decades. For TR-BDF2 (order 2, local error
    per step controlled) the global error goes as ``rtol^(2/3)`` (the step is ``rtol^(1/3)``, the error
    per unit time ``h^2``): the same bound on ``error / rtol^(2/3)``. The error never exceeds 10 rtol
    (the pairs: ``rtol``; TR-BDF2: 10 rtol^(2/3) at 1e-9: the loosest claim the docs make)."""
    p = request.getfixturevalue(scene)
    T = 0.05
    ref = solve_ivp(p.f, (0.0, T), p.x, method="DOP853", rtol=1e-13, atol=1e-15).y[:, -1]
    exponent = 2.0 / 3.0 if name == "trbdf2" else 1.0
    ratios = []
    for rtol in RTOLS:
        code, x, _, _ = p.advance(get_integrator(name, rtol=rtol, atol=rtol * 1e-2), T)
        assert code == integrate.STEP_OK
        err = np.max(np.abs(x[:p.nz] - ref[:p.nz]))
        assert err <= 10.0 * rtol ** exponent, (rtol, err)
        ratios.append(err / rtol ** exponent)
    assert max(ratios) / min(ratios) <= 10.0, ratios


def test_closed_loop_statistics_add_up():
    """A closed-loop run's per-tick statistics: every tick but the last advances; their right-hand-side
    evaluations add up to the run's; ``simulate`` reports the totals and the mean step."""
    scene = coopctrl.load_scenario(SCENARIOS / "planar_two_arm_lift.toml",
                                   {"simulation.integrator": "rk45", "simulation.rtol": "1e-9",
                                    "simulation.duration": "0.2"})
    loop = closed_loop(scene)
    rec = loop.run(build.initial_state(scene), 0.2)
    steps = rec.integration_steps
    assert rec.status == "ok" and steps.shape == (len(rec.t), 4)
    assert np.all(steps[:-1, adaptive.STAT_ACCEPTED] >= 1) and steps[-1, adaptive.STAT_ACCEPTED] == 0
    assert int(steps[:, adaptive.STAT_RHS].sum()) == rec.rhs_evaluations
    result = coopctrl.simulate(scene)
    stats = result.integration_statistics
    assert stats["steps_accepted"] == int(steps[:, 0].sum())
    assert stats["rhs_evaluations"] == rec.rhs_evaluations
    assert math.isclose(result.step_s, 0.2 / stats["steps_accepted"], rel_tol=1e-3)
    summary = result.summary()
    assert summary["steps_accepted"] == stats["steps_accepted"] and "smallest_step_s" in summary


def test_same_state_same_result():
    """Two runs of one loop from the same state give the same record bit for bit (the step carried from
    period to period starts afresh with each run)."""
    scene = coopctrl.load_scenario(SCENARIOS / "planar_two_arm_lift.toml",
                                   {"simulation.integrator": "trbdf2", "simulation.duration": "0.1"})
    loop = closed_loop(scene)
    x0 = build.initial_state(scene)
    a, b = loop.run(x0, 0.1), loop.run(x0, 0.1)
    assert np.array_equal(a.x, b.x) and np.array_equal(a.integration_steps, b.integration_steps, equal_nan=True)


def test_tighter_rtol_is_closer_to_the_fixed_step_reference():
    """In the closed loop of the stiff scene, rk45 and trbdf2 at rtol 1e-9 agree with RK4 at T/16 (its
    error ~ (h omega)^4 / 120 ~ 4e-6 relative per period at omega 5000 rad/s, h = 62.5 us) far better than
    at rtol 1e-3: the tolerance reaches the closed-loop result."""
    base = {"simulation.duration": "0.1"}
    ref = coopctrl.simulate(coopctrl.load_scenario(SCENARIOS / "stiff_grasp_extreme.toml",
                                                   {**base, "simulation.substeps": "16"}))
    for name in ("rk45", "trbdf2"):
        errs = []
        for rtol in ("1e-3", "1e-9"):
            r = coopctrl.simulate(coopctrl.load_scenario(SCENARIOS / "stiff_grasp_extreme.toml",
                                                         {**base, "simulation.integrator": name, "simulation.rtol": rtol,
                                                          "simulation.atol": "1e-12"}))
            assert r.status == "ok"
            errs.append(np.max(np.abs(r.F_measured - ref.F_measured)))
        assert errs[1] < errs[0] / 10.0, (name, errs)


def test_step_below_min_step_stops_with_the_stiffest_mode():
    """rk45 on the stiff grasp (omega_max ~ 5000 rad/s: its stability bound is ~3.3 / 5000 = 0.66 ms) with
    ``min_step`` = 0.9 ms: the run stops at once, naming the step, the bound, the stiff mode and the fix."""
    scene = coopctrl.load_scenario(SCENARIOS / "stiff_grasp_extreme.toml",
                                   {"simulation.integrator": "rk45", "simulation.min_step": "9e-4",
                                    "simulation.duration": "0.05"})
    r = coopctrl.simulate(scene)
    assert r.status == "diverged"
    assert "simulation.min_step = 0.0009 s" in r.reason and "rad/s" in r.reason and '"trbdf2"' in r.reason
    assert "with the object at (" in r.reason  # the state where it failed
    omega = float(r.reason.split(" at ")[-1].split(" rad/s")[0])
    assert 3000.0 < omega < 8000.0  # the grasp's spring mode (stability.py reports omega_max ~ 5000 rad/s)


@pytest.mark.parametrize("key,value,allowed", [
    ("simulation.rtol", "0", ">= 1e-13"), ("simulation.rtol", "0.5", "<= 0.1"), ("simulation.rtol", "nan", "finite"),
    ("simulation.atol", "-1e-8", "> 0"), ("simulation.atol", "inf", "finite"),
    ("simulation.atol_velocity", "0", "> 0"), ("simulation.min_step", "0.01", "< control_period"),
    ("simulation.accuracy", "0", ">= 1e-12"), ("simulation.accuracy", "nan", "finite"),
    ("simulation.integrator", "rk89", "'rk45'"),
])
def test_bad_tolerances_name_the_field(key, value, allowed):
    with pytest.raises(ScenarioError) as info:
        coopctrl.load_scenario(SCENARIOS / "planar_two_arm_lift.toml", {key: value})
    text = str(info.value)
    assert key in text and allowed in text and "\n" not in text


def test_python_api_checks_the_tolerances():
    with pytest.raises(ValueError, match="rtol = 1.0 is invalid"):
        get_integrator("rk45", rtol=1.0)
    with pytest.raises(TypeError, match="atol"):
        get_integrator("rk23", atol="small")



@pytest.mark.parametrize("name", ["rk23", "rk45", "trbdf2"])
def test_an_error_controlled_step_on_a_python_function_meets_its_tolerance(name):
    """A plain Python f runs on the core's error-controlled schemes (the slower path): the undamped oscillator
    x'' = -w^2 x over 0.5 s in one call, against its closed form. The error follows the tolerance: 1000x tighter
    tolerances give at least 10x less error (orders 2 to 5), and the tight run is within 1e-4 of the amplitude."""
    w = 7.0

    def f(t, x, u):
        return np.array([x[1], -w * w * x[0]])

    exact = np.array([np.cos(w * 0.5), -w * np.sin(w * 0.5)])
    errors = []
    for rtol in (1e-5, 1e-8):
        x = get_integrator(name, rtol=rtol, atol=rtol * 1e-2).step(f, 0.0, np.array([1.0, 0.0]), None, 0.5)
        errors.append(np.abs(x - exact).max())
    assert errors[1] < errors[0] / 10 and errors[1] < 1e-4 * w, errors


def test_public_step_below_min_step_names_the_stiffest_mode(planar):
    """The public step stops as the loop does: rk45 at rtol 1e-10 needs steps of ~0.6 ms on the planar
    plant (measured 0.58 ms), below a min_step of 1 ms: StepTooSmall with the step, the bound, the time
    and the stiffest mode at the state it stopped at."""
    from coopctrl.errors import StepTooSmall

    scheme = get_integrator("rk45", rtol=1e-10, atol=1e-12, min_step=1e-3)
    with pytest.raises(StepTooSmall) as info:
        scheme.step(planar.plant.rhs, 0.0, planar.x, planar.tau, 0.02)
    err = info.value
    assert err.step < err.min_step == 1e-3 and err.time == 0.0 and err.integrator == "rk45"
    assert err.omega > 0.0 and err.mode and "the stiffest mode there is" in str(err)
