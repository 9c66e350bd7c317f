"""coopctrl/core/tick.h (coopctrl._core.Tick): the closed loop's tick in the compiled core gives the records of the
numba tick it replaces (coopctrl.loop.kernel.run_ticks), bit for bit, on every configuration it runs: sensor noise
and quantization, the elastic split, the reference path (a QP backend in Python between the tick's phases), a QP
that fails, the tuning probes, the object impedance law, the implicit schemes, and a run continued from
another's final state. Each case runs twice, on the core and on numba (the core's entry refused), and every
recorded array must be equal."""

from __future__ import annotations

import numpy as np
import pytest

import coopctrl
import coopctrl.loop.compiled as compiled
from coopctrl.scenario import build
from coopctrl.controllers.leader_law import object_impedance
from coopctrl.wiring import closed_loop

SCENE = "planar_two_arm_lift"

#: name -> overrides of the lift (a short run of each configuration).
CASES = {
    "noise": {"sensors.joints.noise_std": 1e-4, "sensors.joints.quantization": 2e-5,
              "sensors.object.noise_std": 1e-4, "sensors.object.quantization": 1e-5,
              "sensors.forces.noise_std": 0.5, "sensors.forces.quantization": 0.01},
    "elastic_split": {"load_distribution.split": "elastic"},
    "reference_path": {"load_distribution.solver": "proxsuite"},
    "grip_friction_torque_rows": {"load_distribution.min_grip": 1.0, "load_distribution.friction_coefficient": 0.8,
                                  "load_distribution.torque_limits": True},
    "qp_failed": {"load_distribution.min_grip": 1e4, "load_distribution.torque_limits": True,
                            "load_distribution.max_consecutive_failures": 3, "simulation.start": "unloaded"},
    "implicit_euler": {"simulation.integrator": "implicit_euler"},
}


def _run(loop, duration_s: float, tick: str, monkeypatch, start=None, scenario=None) -> dict:
    """The record of ``loop`` over ``duration_s`` [s], on the core's tick or on numba's."""
    core_used = []
    real = compiled.core_tick_control

    def choose(loop_, cl, plan):
        control = real(loop_, cl, plan) if tick == "core" else None
        core_used.append(control is not None)
        return control

    with monkeypatch.context() as patch:
        patch.setattr(compiled, "core_tick_control", choose)
        N = int(round(duration_s / loop.T)) + 1
        x0 = build.initial_state(scenario, loop) if start is None else None
        rec = compiled.run_compiled(loop, loop.empty_record(N), x0, N, start=start)
    assert core_used and all(used == (tick == "core") for used in core_used), core_used
    return rec


def _assert_same(got: dict, want: dict) -> None:
    assert got["status"] == want["status"], (got["reason"], want["reason"])
    assert got["reason"] == want["reason"]
    for key, value in want.items():
        if isinstance(value, np.ndarray) and key not in ("qp_solve_time_s",):
            np.testing.assert_array_equal(got[key], value, err_msg=key)
    for key in ("rhs_evaluations", "saturated_ticks", "qp_status", "qp_binding"):
        assert got[key] == want[key], key


def _scenario(overrides):
    return coopctrl.load_scenario(SCENE, overrides)


@pytest.mark.parametrize("case", list(CASES))
def test_the_core_tick_records_what_the_numba_tick_records(case, monkeypatch):
    scenario = _scenario(CASES[case])
    loop = closed_loop(scenario)
    got = _run(loop, 0.5, "core", monkeypatch, scenario=scenario)
    want = _run(closed_loop(scenario), 0.5, "numba", monkeypatch, scenario=scenario)
    _assert_same(got, want)
    if case == "qp_failed":  # the case reaches the failure policy: its min_grip is beyond the torque limits
        assert got["status"] == "qp_failed"


def test_the_object_impedance_law_and_the_probes_run_on_the_core_as_on_numba(monkeypatch):
    from coopctrl.tuning.loop_probes import probed_closed_loop

    law = object_impedance(2.0, 40.0, 400.0, 0.05, 1.0, 10.0)
    scenario = _scenario({})
    got = _run(closed_loop(scenario, leader_law=law), 0.4, "core", monkeypatch, scenario=scenario)
    want = _run(closed_loop(scenario, leader_law=law), 0.4, "numba", monkeypatch, scenario=scenario)
    _assert_same(got, want)
    records = []
    for tick in ("core", "numba"):
        loop, leader, followers = probed_closed_loop(scenario)
        leader.offset = np.array([0.002, -0.001, 0.01])
        for probe in followers.values():
            probe.setpoint_offset = np.array([1.0, -2.0, 0.1])
            probe.error_gain = np.array([0.5, 1.0, 2.0])
            probe.measurement_delay = np.array([2, 0, 1])
        records.append(_run(loop, 0.3, tick, monkeypatch, scenario=scenario))
    _assert_same(*records)


def test_a_continued_run_on_the_core_continues_as_on_numba(monkeypatch):
    scenario = _scenario({})
    firsts = [_run(closed_loop(scenario), 0.2, tick, monkeypatch, scenario=scenario) for tick in ("core", "numba")]
    _assert_same(*firsts)
    seconds = [_run(closed_loop(scenario), 0.2, tick, monkeypatch, start=first["final_state"])
               for tick, first in zip(("core", "numba"), firsts)]
    _assert_same(*seconds)


def test_runs_the_core_does_not_take_stay_on_numba():
    """A leader law written in Python, a passive run and an error-controlled scheme use the numba tick."""
    scenario = _scenario({})
    loop = closed_loop(scenario)
    cl = compiled.CompiledLoop(loop)
    plan = compiled.I.make_plan(loop.integrator, loop.plant.state_size, loop.T, 10)
    assert compiled.core_tick_control(loop, cl, plan) is not None

    def own_law(err, dY_ref, dY, ddY_ref, npos, params, a_cmd):
        for a in range(a_cmd.shape[0]):
            a_cmd[a] = ddY_ref[a] + params[0] * err[a]

    from coopctrl.controllers.leader_law import LeaderLaw

    custom = closed_loop(scenario, leader_law=LeaderLaw(own_law, (100.0,)))
    assert compiled.core_tick_control(custom, compiled.CompiledLoop(custom), plan) is None
    adaptive = closed_loop(_scenario({"simulation.integrator": "rk45"}))
    adaptive_plan = compiled.I.make_plan(adaptive.integrator, adaptive.plant.state_size, adaptive.T, 10)
    assert compiled.core_tick_control(adaptive, compiled.CompiledLoop(adaptive), adaptive_plan) is None
