"""Order of accuracy of the integrators in the closed loop (issue 5): the error against the
reference falls like ``h^order`` on a smooth scene.

Scene: ``planar_two_arm_lift`` for 0.2 s (the loaded start and the first 2.5 mm of the lift).
``omega_max`` there is 243 rad/s, so ``h omega_max <= 0.25`` for every step of the grid (T/1 ..
T/8 of T = 1 ms): the asymptotic range of all five schemes, far from any stability limit. The
controller is sampled at the same instants in every run, so the error measured is the
integration error, fed back through the same controller; for a smooth closed loop it is
``O(h^p)`` like the open-loop global error.

The slope is a least-squares fit of ``log(error)`` against ``log(h)``. Tolerance +-0.2: the
orders to tell apart are 1, 2 and 4, and the measured slopes are within 0.05 of them (the
next-order terms are ``O(h omega)`` relative, <= 0.25 at T/1 and 4 times smaller at each halving).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl.analysis.reference import ReferenceIntegrator
from coopctrl.analysis.tradeoff import run_errors, run_loop, run_tradeoff
from coopctrl.integrators import get_integrator
from coopctrl.scenario import build

SCENARIOS = Path(__file__).resolve().parent.parent / "scenarios"
SUBSTEPS = (1, 2, 4, 8)
ORDERS = {"euler": 1, "symplectic_euler": 1, "rk4": 4, "implicit_midpoint": 2, "implicit_euler": 1}
#: Slope tolerance, see the module docstring.
SLOPE_TOLERANCE = 0.2
#: An error enters the fit only if it is this many times the reference's own error: then the
#: reference's error changes the fitted log-error by at most log(1 + 1/10) ~ 0.1 at one point.
RESOLUTION_FACTOR = 10.0
#: Substeps of the independent check of the reference: RK4 at T/64 (h omega_max = 0.004), whose
#: own error (~ error(T/1) / 64^4 ~ 1e-17 m) is below rounding.
FINE_SUBSTEPS = 64


@pytest.fixture(scope="module")
def scene():
    return coopctrl.load_scenario(SCENARIOS / "planar_two_arm_lift.toml", {"simulation.duration": 0.2})


@pytest.fixture(scope="module")
def grid(scene):
    return run_tradeoff(scene, list(ORDERS), SUBSTEPS)


@pytest.fixture(scope="module")
def reference_error(scene):
    """How far the reference is from an independent fine solution: errors per metric."""
    x0 = build.initial_state(scene)
    ref = run_loop(scene, x0, ReferenceIntegrator(), 1)
    fine = run_loop(scene, x0, get_integrator("rk4"), FINE_SUBSTEPS)
    assert ref.status == fine.status == "ok"
    return run_errors(fine, ref)


def test_reference_matches_fine_rk4(reference_error, grid):
    """The reference agrees with RK4 at T/64 to rounding. Rounding over the 200 x 64 fine steps:
    ``eps |r| sqrt(12800) ~ 1.1e-16 * 0.5 m * 113 ~ 6e-15 m``, times the spring stiffness 2e4 N/m
    ~ 1.2e-10 N in force, over a 0.1 m lever ~ 6e-14 rad; the bounds are these, rounded up. They
    are far below the errors the reference is used to measure (RK4 at T/4: 5.6e-13 m, 4.4e-9 N)."""
    assert reference_error["position_error_m"] <= 2e-14
    assert reference_error["orientation_error_rad"] <= 6e-14
    assert reference_error["force_error_N"] <= 2e-10
    # ... and below each integrator's error at T/1 by a wide margin
    for name in ORDERS:
        row = grid.row(name, 1)
        assert row.position_error_m >= 1000 * reference_error["position_error_m"]
        assert row.force_error_N >= 1000 * reference_error["force_error_N"]


def test_grid_takes_the_steps_it_reports(grid):
    """Each row really integrated with h = T / n: the right-hand-side count of the explicit schemes
    is (calls per step) x n x (control periods), exactly."""
    ticks = round(grid.duration_s / grid.control_period_s)
    for name, calls in (("euler", 1), ("symplectic_euler", 1), ("rk4", 4)):
        for n in SUBSTEPS:
            assert grid.row(name, n).rhs_evaluations == calls * n * ticks


def _slope(grid, name, metric, floor):
    rows = [grid.row(name, n) for n in SUBSTEPS]
    assert all(r.status == "ok" for r in rows), [r.reason for r in rows]
    pts = [(r.step_s, getattr(r, metric)) for r in rows if getattr(r, metric) >= RESOLUTION_FACTOR * floor]
    assert len(pts) >= 3, f"{name}: fewer than 3 errors above {RESOLUTION_FACTOR} x the reference's error"
    h, e = np.log(np.array(pts)).T
    return float(np.polyfit(h, e, 1)[0])


@pytest.mark.parametrize("name", list(ORDERS))
@pytest.mark.parametrize("metric", ["position_error_m", "orientation_error_rad", "force_error_N"])
def test_error_slope_matches_order(grid, reference_error, name, metric):
    # the floor is at least one rounding unit of the quantity, so that a zero difference between
    # the reference and the fine run does not admit errors at rounding level
    floor = max(reference_error[metric], {"position_error_m": 1e-15, "orientation_error_rad": 1e-15,
                                          "force_error_N": 1e-11}[metric])
    slope = _slope(grid, name, metric, floor)
    assert slope == pytest.approx(ORDERS[name], abs=SLOPE_TOLERANCE), f"{name} {metric}: slope {slope:.3f}"


def test_orders_reported_by_integrators_match():
    """The orders tested above are the ones the integrators declare."""
    for name, order in ORDERS.items():
        assert get_integrator(name).order == order


def test_halving_the_step_divides_the_error_by_2_to_the_order(grid):
    """The same, pointwise, between T/1 and T/2 for the first-order and second-order schemes, whose
    errors are far above the reference's error at every step (ratio within 10% of 2^p: the
    next-order term is O(h omega_max) <= 0.25 relative at T/1, and halves from T/1 to T/2)."""
    for name in ("euler", "symplectic_euler", "implicit_midpoint", "implicit_euler"):
        ratio = grid.row(name, 1).position_error_m / grid.row(name, 2).position_error_m
        assert ratio == pytest.approx(2 ** ORDERS[name], rel=0.1)
        assert math.isfinite(ratio)
