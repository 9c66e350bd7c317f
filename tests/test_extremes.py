"""Extremes (issue 5): stiffness 1e2..1e9 N/m, node masses 1e-3..1e2 kg, steps 1e-6..1e-2 s.

Every run either ends "ok", with finite records and the accuracy its step promises, or stops with
the divergence diagnostic (time, quantity, and a suggested step below the failing one, or the reason
no step helps), and then its step was beyond the integrator's predicted limit or the physics is the
cause. No run produces NaN silently; every run is at most a few thousand steps, so none hangs.

The sweep is the passive loop (controllers off) of the planar contact-point scene with gravity off:
no controller, so what the integrator meets is exactly the plant that the prediction linearizes, the
total energy is an exact invariant (undamped) or non-increasing (damped), and the control period
``T = 10 h`` does not cap the step. Its excitation is the released squeeze (20 N) of the loaded start,
plus a seeded 1 nm / 1 nrad perturbation of every coordinate (``seeded_start``, as in the stability
measurement): the symmetric scenes otherwise keep some modes at exactly 0.0 in floating point, and an
unstable mode that is never excited cannot show. A closed-loop subset (controllers on, gravity on) and
a spatial case follow.
"""

from __future__ import annotations

import itertools
import math
import re

import numpy as np
import pytest

from coopctrl.analysis.modes import linear_modes
from coopctrl.analysis.stability import seeded_start
from coopctrl.integrators import get_integrator
from coopctrl.integrators.base import Integrator, spectral_radius
from coopctrl.scenario import build, load_scenario
from coopctrl.simulator import closed_loop
from test_cli import REPO
from test_stability import planar_contact_points

STIFFNESS = (1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9)  # N/m
NODE_MASS = (1e-3, 1e-1, 1e1, 1e2)  # kg
STEP = (1e-6, 1e-4, 1e-2)  # s
STEPS_PER_RUN = 200  # plant steps per run: T = 10 h, 20 control periods

#: Largest relative energy drift of an "ok" undamped run with ``h omega_max <= 0.1`` (well resolved):
#: RK4 loses ``|R(i y)|^2 - 1 = -y^6 / 72`` of a mode's energy per step, 1.4e-8 at y = 0.1, so 200 steps
#: drift < 3e-6 (1e-3 leaves room for the spring nonlinearity); implicit midpoint conserves quadratic
#: invariants up to its Newton tolerance (1e-12 relative per step); symplectic Euler conserves a modified
#: energy, the true one oscillating by ~ y / 2 = 5 % around it.
ENERGY_DRIFT = {"rk4": 1e-3, "implicit_midpoint": 1e-6, "symplectic_euler": 0.1}
#: Factor [-] on the energy growth an "ok" run may show beyond the linear one-step map's ``rho^(2 n)``: the
#: non-normal transient of a stable map near its limit and the springs' nonlinearity give a few at most,
#: while an unstable mode's growth is geometric (~1e12 in energy over 200 steps 1 % above an RK4 limit).
ENERGY_BOUND = 100.0

REASON = re.compile(r"^diverged at t = [0-9.e+-]+ s: .+ = ")


def _suggested(reason: str) -> float | None:
    m = re.search(r"try a step of at most ([0-9.e+-]+) s", reason)
    return float(m.group(1)) if m else None


def _modes(scenario):
    return linear_modes(scenario.plant(), build.initial_state(scenario))


def _passive(k, m, damping):
    # max_deformation 1 m: the 1e2 N/m springs deform 0.1 m under the 20 N squeeze (a physical state)
    from dataclasses import replace

    scenario = planar_contact_points(k=k, node_mass=m, damping=damping, torsion=1.0, torsion_damping=0.0,
                                     element="offset", max_deformation=1.0, duration=1.0)
    return replace(scenario, scene=replace(scenario.scene, gravity=0.0))


def _with_step(scenario, h):
    from dataclasses import replace

    sim = replace(scenario.simulation, control_period=10 * h, substeps=10, duration=STEPS_PER_RUN * h)
    return replace(scenario, simulation=sim)


def _run(scenario, integrator, h):
    loop = closed_loop(scenario, integrator=integrator)
    rec = loop.run(seeded_start(build.initial_state(scenario), loop.plant.nz), STEPS_PER_RUN * h)
    return loop, rec


def _check_diverged(loop, rec, h, limit, scenario, integrator):
    """A diverged run: one-line reason with time, quantity and value; the step was beyond the predicted
    limit (10 % margin: the loaded start is released into a finite-amplitude motion) or no step helps;
    the suggested step is below the failing one and runs (the same number of steps: the passive loop's
    control period only sets the sampling)."""
    reason = rec["reason"]
    assert REASON.match(reason), reason
    assert "\n" not in reason
    assert np.all(np.isfinite(rec["x"])), "the records stop at the last finite state"
    suggested = _suggested(reason)
    if limit == 0.0:
        assert "unstable at every step on an undamped mode" in reason
        return
    assert h > 0.9 * limit, (h, limit, reason)
    assert suggested is not None and suggested < h, reason
    _, rec2 = _run(_with_step(scenario, suggested), integrator, suggested)
    assert rec2["status"] == "ok", rec2["reason"]


def _check_ok(rec, h, modes, damped, integrator):
    """An "ok" run: finite records; its energy grows no faster than the linearization's one-step map
    allows (``rho(M(h))^2`` per step, times ENERGY_BOUND for transients and the springs' nonlinearity):
    at a step inside the predicted limit ``rho <= 1``, so at most ENERGY_BOUND; and when the step resolves
    the fastest mode (``h omega_max <= 0.1``) the accuracy of its order (ENERGY_DRIFT; a damped run may not
    gain energy at all)."""
    for key in ("x", "energy", "F_measured", "r_contacts"):
        assert np.all(np.isfinite(rec[key])), key
    E = rec["energy"]
    E0 = E[0]
    assert E0 > 0
    scheme = get_integrator(integrator)
    rho = spectral_radius(Integrator.one_step_matrix(scheme, modes.A, h))
    steps = np.arange(len(E)) * 10
    with np.errstate(over="ignore"):
        allowed = E0 * ENERGY_BOUND * max(rho, 1.0) ** (2 * steps)
    assert np.all(E <= allowed), (integrator, h, rho, E / E0)
    omega = modes.omega_max
    if integrator == "euler" and not damped:
        # explicit Euler multiplies a mode's energy by exactly 1 + (h omega)^2 per step: it grows at every
        # step (no stable step without damping), and by no more than the fastest mode's factor
        assert E[-1] > E0
        assert np.all(E <= E0 * (1.0 + (h * omega) ** 2) ** steps * (1.0 + 1e-6))
    elif integrator == "implicit_euler":
        # L-stable and dissipative at every step, resolved or not: on the linearization each mode's energy
        # is multiplied by 1 / (1 + (h omega_i)^2) per step, so the energy never rises (1e-12: round-off of
        # the energy sum; measured rises <= 4e-16) and, undamped, falls no faster than the fastest mode's
        # (1e-6 for the springs' nonlinearity; measured: never faster)
        assert np.all(np.diff(E) <= 1e-12 * E0), (h, np.max(np.diff(E)) / E0)
        if not damped:
            with np.errstate(under="ignore"):
                floor = E0 * (1.0 + (h * omega) ** 2) ** -steps.astype(float)
            assert np.all(E >= floor * (1.0 - 1e-6)), (h, omega, np.min(E / floor))
    elif h * omega <= 0.1 and h <= modes.predicted_max_step(scheme):
        if damped:
            # damping only dissipates; a resolved stable step must not add energy (its error is ~1e-8 per
            # step); symplectic Euler's true energy oscillates about its modified one
            if integrator != "symplectic_euler":
                assert np.max(E) <= E0 * (1 + 1e-6), (integrator, h, np.max(E) / E0)
        else:
            drift = np.max(np.abs(E - E0)) / E0
            assert drift <= ENERGY_DRIFT[integrator], (integrator, h, omega, drift)


@pytest.mark.parametrize("damping", [0.0, 60.0], ids=["undamped", "damped"])
@pytest.mark.parametrize("k", STIFFNESS)
def test_passive_sweep(k, damping):
    """For each stiffness: every node mass, every step, every integrator."""
    outcomes = []
    for m in NODE_MASS:
        base = _passive(k, m, damping)
        modes = _modes(base)
        for h in STEP:
            scenario = _with_step(base, h)
            for name in ("rk4", "symplectic_euler", "implicit_midpoint", "implicit_euler", "euler"):
                limit = modes.predicted_max_step(get_integrator(name))
                loop, rec = _run(scenario, name, h)
                outcomes.append((m, h, name, rec["status"]))
                if rec["status"] == "ok":
                    _check_ok(rec, h, modes, damping > 0, name)
                else:
                    assert rec["status"] == "diverged", rec["reason"]
                    _check_diverged(loop, rec, h, limit, scenario, name)
    statuses = {o[3] for o in outcomes}
    if k >= 1e6:  # h = 1e-2 s is far beyond every explicit limit there: the sweep is not vacuous
        assert statuses == {"ok", "diverged"}, outcomes
    # the unconditionally stable schemes never diverge, at any stiffness, mass or step
    assert all(o[3] == "ok" for o in outcomes if o[2] in ("implicit_midpoint", "implicit_euler")), outcomes


def test_every_combination_is_classified_by_the_prediction():
    """RK4, undamped: over the whole grid, a run diverges exactly when its step is beyond the predicted
    limit by more than 10 %, and stays ok when below 90 % of it (the band between is either)."""
    disagreements = []
    for k, m in itertools.product(STIFFNESS, NODE_MASS):
        base = _passive(k, m, 0.0)
        limit = _modes(base).predicted_max_step(get_integrator("rk4"))
        for h in STEP:
            _, rec = _run(_with_step(base, h), "rk4", h)
            if (h > 1.1 * limit and rec["status"] == "ok") or (h < 0.9 * limit and rec["status"] != "ok"):
                disagreements.append((k, m, h, limit, rec["status"]))
    assert not disagreements


@pytest.mark.parametrize("k", [1e2, 1e5, 1e9])
def test_closed_loop_extremes(k):
    """The two-arm lift (controllers on, gravity on) at soft, nominal and very stiff grasps, 20 ms at a step
    well inside RK4's limit (h omega_max ~ 0.3). Soft (1e2 N/m): the loaded start already deforms the grasps
    0.2 m > max_deformation, stopped at t = 0 saying so (physics, not the step). Otherwise ok, and the object
    follows a run at a 4 times smaller step to 1e-7 m, three orders below the tracking error the controllers
    reach (~1e-4 m); measured 7e-12 m at 1e5 N/m, 1.3e-8 m at 1e9 N/m, where 3300 steps at h omega = 0.3
    accumulate RK4's phase error on a mode the controller re-excites every tick."""
    overrides = {"springs[0].stiffness": k, "springs[1].stiffness": k, "simulation.duration": 0.02}
    scenario = load_scenario(REPO / "scenarios" / "planar_two_arm_lift.toml", overrides)
    omega = _modes(scenario).omega_max
    T = scenario.simulation.control_period
    substeps = max(1, math.ceil(T * omega / 0.3))

    def run(n):
        loop = closed_loop(scenario)
        loop.set_step(T / n)
        return loop.run(build.initial_state(scenario), 0.02)

    rec = run(substeps)
    if k == 1e2:
        assert rec["status"] == "diverged"
        assert "diverged at t = 0 s: deformation" in rec["reason"]
        assert "not the likely cause" in rec["reason"] and "too soft" in rec["reason"]
        return
    assert rec["status"] == "ok", rec["reason"]
    assert np.all(np.isfinite(rec["x"]))
    fine = run(4 * substeps)
    nz, p = closed_loop(scenario).plant.nz, 3
    err = np.max(np.abs(rec["x"][:, nz - p:nz - 1] - fine["x"][:, nz - p:nz - 1]))
    assert err <= 1e-7, err


def test_closed_loop_stiff_grasp_at_a_coarse_step_stops_with_a_working_suggestion():
    """1e9 N/m at h = T = 1 ms (h omega_max ~ 58, twenty times RK4's limit): stopped within a few ticks;
    the suggested step (half the predicted limit) runs the same 20 ms."""
    overrides = {"springs[0].stiffness": 1e9, "springs[1].stiffness": 1e9, "simulation.duration": 0.02}
    scenario = load_scenario(REPO / "scenarios" / "planar_two_arm_lift.toml", overrides)
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario)
    rec = loop.run(x0, 0.02)
    assert rec["status"] == "diverged" and REASON.match(rec["reason"])
    suggested = _suggested(rec["reason"])
    assert suggested is not None and suggested < 1e-3
    assert suggested == pytest.approx(0.5 * loop.predicted_max_step(x0), rel=0.01)
    loop = closed_loop(scenario)
    loop.set_step(suggested)
    assert loop.run(x0, 0.02)["status"] == "ok"


@pytest.mark.parametrize("k, h", [(1e2, 1e-2), (1e9, 1e-6), (1e9, 1e-4)])
def test_spatial_passive_extremes(k, h):
    """The spatial contact-point scene, passive and undamped (gravity off): resolved runs conserve energy
    (RK4, see ENERGY_DRIFT), the unresolved one (1e9 N/m at 0.1 ms, h omega ~ 7) stops with the diagnostic."""
    overrides = {"controllers.enabled": False, "scene.gravity": 0.0, "simulation.max_deformation": 1.0,
                 **{f"springs[{i}].{key}": k for i in (0, 1) for key in ("stiffness",)},
                 **{f"springs[{i}].{key}": 0.0 for i in (0, 1) for key in ("damping", "torsion_damping")}}
    base = load_scenario(REPO / "scenarios" / "contact_points_only.toml", overrides)
    modes = _modes(base)
    limit = modes.predicted_max_step(get_integrator("rk4"))
    scenario = _with_step(base, h)
    loop, rec = _run(scenario, "rk4", h)
    if h < 0.9 * limit:
        assert rec["status"] == "ok", rec["reason"]
        _check_ok(rec, h, modes, False, "rk4")
    else:
        assert rec["status"] == "diverged"
        _check_diverged(loop, rec, h, limit, scenario, "rk4")
