"""Seeded fuzz of the Python API with wrong types, shapes and values (issue 22, "The Python API").

Every public call with one argument replaced by a wrong value raises ``TypeError`` or ``ValueError``
whose one-line message names that argument, and nothing else (no ``AttributeError``, no numba
``TypingError``, no broadcasting error, no run that returns). One small planar loop is built once
and reused; every refusal comes before any simulation, so the calls take well under a second.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import coopctrl
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

#: Draws of (call, argument, wrong value); the pools below are small, so 600 draws cover every pair
#: several times, and the seed makes the draw order and the corrupted entries reproducible.
DRAWS = 600
SEED = 22


@pytest.fixture(scope="module")
def planar():
    """The default scene (planar, two arms), its closed loop and its loaded initial state (no run)."""
    scenario = coopctrl.load_scenario(None)
    loop = closed_loop(scenario)
    return scenario, loop, build.initial_state(scenario)


class _Opaque:
    """An object of no expected kind."""

    def __repr__(self) -> str:
        return "<opaque>"


def _wrong_states(rng, x0) -> list:
    """States that are not ``state_size`` finite numbers: wrong types, shapes, and a NaN/inf entry at a
    seeded place."""
    n = x0.size
    bad = x0.copy()
    bad[rng.integers(n)] = rng.choice([np.nan, np.inf, -np.inf])
    return [None, "x0", b"\x00", {"x": 1.0}, _Opaque(), 3.0, np.append(x0, 0.0), x0[:-1], x0.reshape(2, -1),
            np.zeros((n, 1)), [list(x0), list(x0)], ["a"] * n, bad, list(bad), np.zeros(0), [[1.0], [2.0, 3.0]]]


def _cases(scenario, loop, x0, rng):
    """``(name, argument, value, call)`` of every wrong value of every checked argument."""
    T = loop.T
    wrong_durations = [math.nan, math.inf, -math.inf, -1.0, -1e-3, "1", None, [0.1], 1j, True, _Opaque()]
    wrong_flags = ["yes", 1, 0, None, 1.0, [True], _Opaque()]
    wrong_scenarios = [None, {}, {"arms": []}, "planar_two_arm_lift", Path("scenario.toml"), [scenario], 3, loop,
                       _Opaque()]
    wrong_steps = [0.0, -T, math.nan, math.inf, "0.001", None, [T], True, 10.0 * T]
    wrong_integrals = [[0.0, 0.0, 0.0], "1", 3, {0: [0.0] * loop.plant.p}, {"1": [0.0] * loop.plant.p},
                       {True: [0.0] * loop.plant.p}, {1: [0.0] * (loop.plant.p + 1)}, {1: [math.nan] * loop.plant.p},
                       {1: None}]
    follower = sorted(loop.followers)[0]
    ok_integrals = {follower: np.zeros(loop.plant.p)}
    cases = []
    for v in _wrong_states(rng, x0):
        cases += [("run", "x0", v, lambda v=v: loop.run(v, 0.05)),
                  ("modes", "x", v, lambda v=v: loop.modes(v)) if v is not None else None,
                  ("predicted_max_step", "x", v, lambda v=v: loop.predicted_max_step(v)) if v is not None else None,
                  ("diagnose", "x", v, lambda v=v: loop.diagnose(v)),
                  ("loaded_state", "x_unloaded", v, lambda v=v: loop.loaded_state(v))]
    plant, u = loop.plant, np.zeros(loop.plant.input_size)
    for v in _wrong_states(rng, x0)[:12]:  # the plant checks sizes only: a NaN state is the physics' to report
        cases += [("plant.rhs", "x", v, lambda v=v: plant.rhs(0.0, v, u)),
                  ("plant.node_poses", "x", v, lambda v=v: plant.node_poses(v)),
                  ("plant.energy", "x", v, lambda v=v: plant.energy(v)),
                  ("plant.contact_wrenches", "x", v, lambda v=v: plant.contact_wrenches(v)),
                  ("plant.control_terms", "x", v, lambda v=v: plant.control_terms(v)),
                  ("plant.leader_follower", "x", v, lambda v=v: plant.leader_follower(v)),
                  ("plant.jacobians", "x_eq", v, lambda v=v: plant.jacobians(v, u))]
    for v in [None, "tau", np.append(u, 0.0), u[:-1], np.zeros((2, u.size))]:
        cases += [("plant.rhs", "tau", v, lambda v=v: plant.rhs(0.0, x0, v)),
                  ("plant.jacobians", "tau_eq", v, lambda v=v: plant.jacobians(x0, v))]
    for v in wrong_durations:
        cases.append(("run", "duration", v, lambda v=v: loop.run(x0, v)))
    for v in wrong_flags:
        cases += [("run", "progress", v, lambda v=v: loop.run(x0, 0.05, progress=v)),
                  ("simulate", "progress", v, lambda v=v: coopctrl.simulate(scenario, progress=v)),
                  ("set_step", "uniform", v, lambda v=v: loop.set_step(T, uniform=v)),
                  ("closed_loop", "uniform_step", v, lambda v=v: closed_loop(scenario, uniform_step=v))]
    for v in wrong_integrals:
        cases.append(("run", "integrals", v, lambda v=v: loop.run(x0, 0.05, integrals=v)))
    cases.append(("run", "integrals", ok_integrals, None))  # a valid mapping: the draw below skips it
    for v in wrong_scenarios:
        cases += [("simulate", "scenario", v, lambda v=v: coopctrl.simulate(v)),
                  ("closed_loop", "scenario", v, lambda v=v: closed_loop(v))]
    for v in wrong_steps:
        cases += [("set_step", "step", v, lambda v=v: loop.set_step(v)),  # closed_loop's step=None: T / substeps
                  ("closed_loop", "step", v, lambda v=v: closed_loop(scenario, step=v)) if v is not None else None]
    for v in [3, 2.5, [], _Opaque(), {"name": "rk4"}]:
        cases.append(("closed_loop", "integrator", v, lambda v=v: closed_loop(scenario, integrator=v)))
    for v in ["bogus", ""]:
        cases.append(("closed_loop", "integrator", v, lambda v=v: closed_loop(scenario, integrator=v)))
    for v in [3, "f", [], {}]:
        cases.append(("closed_loop", "controllers", v, lambda v=v: closed_loop(scenario, controllers=v)))
    for v in [3, 2.5, b"scenario.toml", ["scenario.toml"], {"path": "x"}, True, _Opaque()]:
        cases.append(("load_scenario", "path", v, lambda v=v: coopctrl.load_scenario(v)))
    for v in [["simulation.duration=1"], "simulation.duration=1", ("a", 1), 3, {1: 2}, {None: "x"}, _Opaque()]:
        cases.append(("load_scenario", "overrides", v, lambda v=v: coopctrl.load_scenario(None, overrides=v)))
    return [c for c in cases if c is not None and c[3] is not None]


def test_every_wrong_argument_is_a_type_or_value_error_naming_it(planar):
    scenario, loop, x0 = planar
    rng = np.random.default_rng(SEED)
    cases = _cases(scenario, loop, x0, rng)
    T = loop.T
    failures, drawn = [], set()
    for k in rng.integers(len(cases), size=DRAWS):
        name, argument, value, call = cases[k]
        drawn.add((name, argument))
        try:
            call()
        except (TypeError, ValueError) as exc:
            message = str(exc)
            if argument not in message or "\n" in message or "is invalid" not in message:
                failures.append(f"{name}({argument}={value!r}): unclear {type(exc).__name__}: {message}")
        except Exception as exc:  # noqa: BLE001 - anything else is the failure this test looks for
            failures.append(f"{name}({argument}={value!r}): {type(exc).__name__}: {str(exc)[:200]}")
        else:
            failures.append(f"{name}({argument}={value!r}) returned")
        finally:
            if loop.T != T or loop.h > T:  # a refused set_step must leave the loop as it was
                failures.append(f"{name}({argument}={value!r}) changed the loop's step")
    assert failures == []
    assert drawn == {c[:2] for c in cases}  # every checked argument of every call was tried


def test_one_extra_state_entry_is_refused_not_run(planar):
    """The issue's example: ``closed_loop(sc).run(x0_with_one_extra_entry, 0.05)`` returned ok."""
    _, loop, x0 = planar
    with pytest.raises(ValueError, match=rf"x0 = .* expected .*{x0.size} finite numbers .*got \({x0.size + 1},\)"):
        loop.run(np.append(x0, 0.0), 0.05)


@pytest.mark.parametrize("value, kind", [({}, TypeError), ("planar_two_arm_lift", TypeError)])
def test_simulate_says_how_to_get_a_scenario(value, kind):
    with pytest.raises(kind, match=r"scenario = .*load_scenario\(path\)"):
        coopctrl.simulate(value)


def test_valid_arguments_still_pass_the_checks(planar):
    """The checks accept what the API documents: numpy scalars and bools, a list state, a Path."""
    scenario, loop, x0 = planar
    from coopctrl.wiring import check_arguments

    check_arguments(scenario, integrator="rk4", step=np.float64(loop.T / 2), uniform_step=np.bool_(True))
    assert loop.run(list(x0), 0.0)["x"].shape == (1, x0.shape[0])  # a list state
    first = np.int64(sorted(loop.followers)[0])  # a numpy integer arm index
    assert loop.run(x0, 0.0, integrals={first: [0.0] * loop.plant.p})["status"] == "ok"
