"""The integrators' one source, the compiled core's schemes (coopctrl/core: explicit_schemes.h, implicit_schemes.h,
on the plans of :mod:`coopctrl.integrators.compiled`): the five integrators, the implicit ones with their Newton
iteration, stepping a plant in the core (``coopctrl._core.plant_advance``, as the loop's tick does) against the
numpy oracle of ``tests/_integrator_oracle.py`` (itself checked against scipy in ``tests/test_integrator_oracle.py``)
one step at a time; the public ``Integrator.step`` (on a plant's ``rhs``, and on any Python ``f``) against the core;
and whole closed-loop runs against the Python tick with the plant stepped outside the core. (The core's inverse and
pseudo-inverse are checked against numpy in tests/test_core_integrators.py.)"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

import coopctrl
import coopctrl.integrators.compiled as integrate
from coopctrl import _core
from _integrator_oracle import SDIRK, oracle_step
from coopctrl.integrators import DiagonallyImplicitRungeKutta, ImplicitEuler, NewtonConvergenceError, get_integrator
from coopctrl.loop.build import compiled_unsupported
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ROOT / "scenarios"
IMPLICIT = ("implicit_midpoint", "implicit_euler")
COMPILED = {"load_distribution.solver": "compiled"}
#: The reference path: the Python tick with the oracle's integrator (and proxsuite at eps_abs 1e-9).
REFERENCE = {"load_distribution.solver": "proxsuite", "load_distribution.eps_abs": 1e-9}
ARRAYS = ("t", "x", "tau", "F_measured", "F_commanded", "F_external", "F_internal", "r_contacts")
#: The correction in a Newton failure message: ``(last correction 3.56e-12)``.
CORRECTION = re.compile(r"last correction [-+.e0-9a-z]+")


def _scene(name, **overrides):
    return coopctrl.load_scenario(SCENARIOS / f"{name}.toml", overrides)


class _Plant:
    """A scene's plant, its kernel arrays and a seeded state away from equilibrium (so every spring
    and damper works): ``x0 + 1e-3 N(0, 1)`` and torques ``0.1 N(0, 1)`` N m (seeded generator)."""

    def __init__(self, name: str, seed: int = 7):
        scene = _scene(name)
        self.plant = plant = closed_loop(scene).plant
        rng = np.random.default_rng(seed)
        x0 = build.initial_state(scene)
        self.x = x0 + 1e-3 * rng.standard_normal(x0.shape)
        self.tau = 0.1 * rng.standard_normal(plant.input_size)
        self.P = plant.plant_args  # the kernel arrays by name

    def kernel_steps(self, integrator, h: float, n: int):
        """``n`` steps of ``h`` by the compiled core on the plant's own kernels (one period of one step each, the
        plan kept between them): the states after each step, the plan and the right-hand-side count."""
        plan = integrate.make_plan(integrator, self.x.size)
        status, report = np.zeros(2, np.int64), _core.StopReport()
        x, x_fail, states, codes = self.x.copy(), self.x.copy(), [], []
        for _ in range(n):
            codes.append(_core.plant_advance(plan, x, self.tau, self.P, status, 0.0, np.array([h]), x_fail, report))
            states.append(x.copy())
        return codes, states, plan, report

    def python_steps(self, step, h: float, n: int):
        """The same with ``step(f, t, x, u, h)`` (the oracle's, or a scheme's public ``step``) on the
        plant's ``rhs`` wrapped in a counting Python function: states and right-hand-side calls."""
        calls = [0]
        rhs = self.plant.rhs

        def f(t, x, u):  # one function for every step: the integrator keeps its matrix for it
            calls[0] += 1
            return rhs(t, x, u)

        x, states = self.x.copy(), []
        for _ in range(n):
            x = step(f, 0.0, x, self.tau, h)
            states.append(x)
        return states, calls[0]


class _SDIRK2(DiagonallyImplicitRungeKutta):
    """Two-stage L-stable SDIRK (Alexander 1977), gamma = 1 - 1/sqrt(2), as in tests/test_integrators.py:
    the kernel's multi-stage path (the known part of a later stage, a stage's predictor from the
    previous one). Not registered, so a loop never runs it compiled; the plan takes any tableau."""
    # a user's subclass with a tableau only: its step is the compiled source too

    name = "sdirk2"
    order = 2
    tableau = ((1.0 - 1.0 / math.sqrt(2.0),), (1.0 / math.sqrt(2.0), 1.0 - 1.0 / math.sqrt(2.0)))
    weights = (1.0 / math.sqrt(2.0), 1.0 - 1.0 / math.sqrt(2.0))
    stability_numerator = (1.0, math.sqrt(2.0) - 1.0)


@pytest.fixture(scope="module")
def planar():
    return _Plant("planar_two_arm_lift")


@pytest.mark.parametrize("name", ["euler", "symplectic_euler", "rk4"])
def test_explicit_steps_are_the_oracle_arithmetic(planar, name):
    """The explicit schemes repeat the oracle's numpy operations element by element: bit-identical. The
    public ``step`` gives the kernel's bits too, compiled on the plant's ``rhs`` and run by Python on a
    Python function of it."""
    codes, states, _, report = planar.kernel_steps(get_integrator(name), 1e-3, 3)
    expected, calls = planar.python_steps(oracle_step(get_integrator(name)), 1e-3, 3)
    assert codes == [integrate.STEP_OK] * 3
    for got, want in zip(states, expected):
        np.testing.assert_array_equal(got, want)
    assert report.rhs_evaluations == calls
    interpreted, interpreted_calls = planar.python_steps(get_integrator(name).step, 1e-3, 3)
    assert interpreted_calls == calls
    scheme, x = get_integrator(name), planar.x.copy()
    for got, want in zip(interpreted, states):
        np.testing.assert_array_equal(got, want)
        x = scheme.step(planar.plant.rhs, 0.0, x, planar.tau, 1e-3)
        np.testing.assert_array_equal(x, want)


@pytest.mark.parametrize("scene, name, h, steps, jacobians", [
    ("planar_two_arm_lift", "implicit_midpoint", 1e-3, 4, 1),
    ("planar_two_arm_lift", "implicit_euler", 1e-3, 4, 1),
    # at h omega_max ~ 100 Newton converges slowly on the first steps: the Jacobian is refreshed within a
    # step (rate > reuse_rate) and after a slow step; the reuse policy must take the same decisions
    ("stiff_grasp_extreme", "implicit_euler", 3e-3, 6, 4),
    ("planar_two_arm_lift", _SDIRK2, 1e-3, 4, 1),
])
def test_implicit_steps_match_the_oracle(scene, name, h, steps, jacobians):
    """Several implicit steps from one seeded state, the Newton state (matrix, predictors) kept between them.

    The same iteration path: the same number of right-hand-side calls (Jacobian columns included) and
    of Jacobian evaluations. The decisions it is made of are far from their thresholds on these
    states (the stopping corrections at least 5 % away from the tolerance, the contraction rates at
    least 0.5 % away from reuse_rate = 0.1, measured), against differences between the paths of
    ~1e-13 relative (the LU inverse and the matrix-vector product round differently from LAPACK and
    BLAS). The states then differ by what Newton leaves unresolved: the final correction times the
    contraction rate, below the Newton tolerance ``atol + rtol max|x|`` per step; the bound is the
    tolerance times the number of steps (the schemes are A-stable: an earlier difference does not grow).
    Measured: 6e-17 (planar), 3.5e-13 m (stiff, 6 steps) against bounds of 7e-12 and 1.1e-11.
    """
    case = _Plant(scene)
    new = name if isinstance(name, type) else (lambda: get_integrator(name))
    ki, pi = new(), new()
    oracle = SDIRK(pi)
    codes, states, plan, report = case.kernel_steps(ki, h, steps)
    expected, calls = case.python_steps(oracle.step, h, steps)
    assert codes == [integrate.STEP_OK] * steps
    assert report.rhs_evaluations == calls
    assert plan.memo[2] == oracle.jacobian_evaluations == jacobians
    tol = pi.atol + pi.rtol * max(np.abs(x).max() for x in expected)
    diff = max(np.abs(a - b).max() for a, b in zip(states, expected))
    assert diff <= steps * tol, (diff, steps * tol)
    # the public step on the plant's rhs is the kernel: the same bits and the same Jacobians
    x = case.x.copy()
    for want in states:
        x = pi.step(case.plant.rhs, 0.0, x, case.tau, h)
        np.testing.assert_array_equal(x, want)
    assert pi.jacobian_evaluations == jacobians


def test_newton_failure_is_the_oracle_exception():
    """Two Newton iterations at h = 50 ms from a state moving fast: both paths give up at the same
    stage with a correction far above the tolerance (6e-4 against 1e-12); the same exception class,
    time, step, iterations, and the same message (the correction compared to 1e-9 relative: the
    paths' rounding differs in its last digits)."""
    case = _Plant("planar_two_arm_lift")
    case.x[case.x.size // 2:] += 0.5  # every velocity 0.5 m/s or rad/s: a strongly nonlinear step
    h = 0.05
    codes, _, _, report = case.kernel_steps(ImplicitEuler(max_iterations=2), h, 1)
    with pytest.raises(NewtonConvergenceError) as info:
        case.python_steps(SDIRK(ImplicitEuler(max_iterations=2)).step, h, 1)
    want = info.value
    assert codes == [integrate.STEP_NEWTON_FAILED]
    got = integrate.newton_failure("implicit_euler", np.array([h]), report)
    assert type(got) is NewtonConvergenceError and isinstance(got, ArithmeticError)
    assert (got.time, got.step, got.iterations, got.scheme) == (want.time, want.step, want.iterations, want.scheme)
    assert want.value > 1e3 * (1e-14 + 1e-12 * np.abs(case.x).max())
    assert got.value == pytest.approx(want.value, rel=1e-9)
    assert CORRECTION.sub("", str(got)) == CORRECTION.sub("", str(want))
    assert str(got).startswith("implicit_euler: Newton did not converge at t = 0 s with h = 0.05 s after 2 iterations")


class _Outside:
    """A user-defined integrator: the oracle of the scheme ``inner`` stepping the plant between kernel
    calls (the kernel's plant block is bypassed: :func:`coopctrl.loop.build.integrator_outside`),
    under the inner scheme's name."""

    def __init__(self, inner):
        self.inner = inner
        self.oracle = SDIRK(inner)

    def __getattr__(self, name):
        return getattr(self.inner, name)

    def step(self, f, t, x, u, h):
        return self.oracle.step(f, t, x, u, h)

    def reset(self):
        self.oracle.reset()


def _run_both(name, integrator, duration, step=None, **overrides):
    """The compiled path (compiled QP, compiled integrator) and the reference path (proxsuite, and the
    oracle stepping the plant outside the kernel), both through the same tick."""
    runs = []
    for solver in (COMPILED, REFERENCE):
        scene = _scene(name, **solver, **overrides)
        scheme = integrator() if solver is COMPILED else _Outside(integrator())
        loop = closed_loop(scene, integrator=scheme, step=step)
        assert (compiled_unsupported(loop) is None) == (solver is COMPILED)
        runs.append(loop.run(build.initial_state(scene), duration))
    return runs


@pytest.mark.parametrize("name", IMPLICIT)
@pytest.mark.parametrize("scene, duration, step", [
    ("spatial_two_puma_carry", 0.05, None),
    ("planar_two_arm_lift", 0.1, None),
    # the free step: two steps of 0.4 ms and a remainder of 0.2 ms per period; the step changes within
    # the period, so every step starts cold (a new matrix), as in the oracle
    ("planar_two_arm_lift", 0.05, 4e-4),
])
def test_compiled_implicit_run_agrees_with_the_reference_path(name, scene, duration, step):
    """Compiled against the Python tick with the oracle stepping the plant: contact forces within 1e-6 N and the
    object within 1e-9 m (the bounds of the explicit schemes in tests/test_loop.py). The plant steps
    agree to the Newton tolerance (1e-12 relative, see above) and the QPs to proxsuite's eps_abs 1e-9;
    the loop carries these differences along. Measured: 8e-12 N and 3e-16 m (carry, 0.1 s)."""
    rc, rr = _run_both(scene, lambda: get_integrator(name), duration, step=step)
    assert rc["status"] == rr["status"] == "ok"
    assert len(rc["t"]) == len(rr["t"]) == round(duration / 1e-3) + 1
    p = rr["F_measured"].shape[2]
    npos = 3 if p == 6 else 2
    nz = rr["x"].shape[1] // 2
    for field in ("F_measured", "F_commanded"):
        assert np.abs(rc[field] - rr[field]).max() <= 1e-6, field
    assert np.abs(rc["x"][:, nz - p:nz - p + npos] - rr["x"][:, nz - p:nz - p + npos]).max() <= 1e-9


def test_newton_failure_in_the_loop_gives_the_python_diagnosis():
    """The kernel's Newton failure becomes the same NewtonConvergenceError, so the run stops at the same
    tick with the same status, reason and events as the Python tick (correction masked, see above).
    At h = T = 50 ms with two Newton iterations the second tick's stage fails with a correction of
    6e-4, far above the tolerance."""
    rc, rr = _run_both("planar_two_arm_lift", lambda: ImplicitEuler(max_iterations=2), 0.5, step=0.05,
                       **{"simulation.control_period": 0.05})
    assert rc["status"] == rr["status"] == "diverged"
    assert "implicit_euler: Newton did not converge at t = 0.05 s with h = 0.05 s after 2 iterations" in rr["reason"]
    assert CORRECTION.sub("", rc["reason"]) == CORRECTION.sub("", rr["reason"])
    assert [e[:2] for e in rc["events"]] == [e[:2] for e in rr["events"]]
    assert len(rc["t"]) == len(rr["t"]) == 2


def test_compiled_implicit_runs_are_repeatable():
    """The plan (Newton matrix, predictors) is made afresh per run: the same loop run twice, and a second
    loop from the same scenario, record the same bits."""
    scene = _scene("planar_two_arm_lift", **COMPILED)
    x0 = build.initial_state(scene)
    loop = closed_loop(scene, integrator=get_integrator("implicit_midpoint"))
    first, second = loop.run(x0, 0.1), loop.run(x0, 0.1)
    other = closed_loop(scene, integrator=get_integrator("implicit_midpoint")).run(x0, 0.1)
    assert first["status"] == "ok" and len(first["t"]) == 101
    for rec in (second, other):
        for key in ARRAYS:
            np.testing.assert_array_equal(first[key], rec[key], err_msg=key)
        assert rec["rhs_evaluations"] == first["rhs_evaluations"]


def test_plans_by_scheme():
    """The explicit schemes share one plan type (one compiled loop), the implicit ones another, with
    their tableau and Newton settings; anything else has no compiled step."""
    assert type(integrate.make_plan(get_integrator("rk4"), 4)) is integrate.ExplicitPlan
    assert integrate.make_plan(get_integrator("euler"), 4).method == integrate.METHOD_EULER
    plan = integrate.make_plan(get_integrator("implicit_midpoint", rtol=1e-10, max_iterations=7), 4)
    assert type(plan) is integrate.ImplicitPlan
    assert plan.tableau.tolist() == [[0.5]] and plan.nodes.tolist() == [0.5] and plan.weights.tolist() == [1.0]
    assert plan.settings.tolist() == [1e-10, 1e-14, 7.0, 0.1]
    assert integrate.make_plan(get_integrator("implicit_euler"), 4).tableau.tolist() == [[1.0]]
    with pytest.raises(TypeError, match="has no compiled step"):
        integrate.make_plan(object(), 4)
