"""Short reprs of the result and configuration objects a notebook displays (issue 21 item 6).

``repr(SimulationResult)`` printed whole arrays and 1001 ``'solved'`` strings; the tuning objects
printed 21 x 21 matrices. Each class below is filled with such contents (no simulation is run) and its
repr must stay within :data:`~coopctrl.compact_repr.MAX_LINES` lines and still name what it shows.
"""

from __future__ import annotations

import dataclasses
import importlib

import numpy as np
import pytest

from coopctrl.compact_repr import LINE_WIDTH, MAX_LINES, compact_repr, value_text

N = 1001  # samples of a 1 s run at 1 ms, as in the issue

#: Every result or report class a notebook user would display, by module.
CLASSES = {
    "coopctrl.tuning.closed_loop_model": ["ClosedLoopModel"],
    "coopctrl.tuning.elastic_modes": ["ElasticModes"],
    "coopctrl.tuning.force_loop": ["ForceLoop"],
    "coopctrl.tuning.force_loop_design": ["ForceLoopDesign"],
    "coopctrl.tuning.frequency": ["Margins"],
    "coopctrl.tuning.leader_design": ["LeaderLQRDesign"],
    "coopctrl.tuning.leader_loop": ["LeaderLoop"],
    "coopctrl.tuning.nonlinear_step": ["StepComparison"],
    "coopctrl.tuning.one_period_map": ["OnePeriodMap"],
    "coopctrl.tuning.operating_point": ["OperatingPoint"],
    "coopctrl.tuning.plant_model": ["PlantModel"],
    "coopctrl.analysis.closed_loop_stability": ["LoopLinearization", "ClosedLoopLimit", "LoopLinearizer", "ModeProbe"],
    "coopctrl.analysis.fidelity": ["PlaneTrace", "PlanarTask", "FidelityModel", "FidelityReport"],
    "coopctrl.analysis.preflight": ["PreflightIssue", "PreflightReport"],
    "coopctrl.analysis.stability": ["StabilityRow", "StabilityReport"],
    "coopctrl.analysis.tradeoff": ["LoopRun", "TradeoffRow", "ReferenceSummary", "TradeoffResult"],
    "coopctrl.sweep.plan": ["SweepRun", "SweepPlan"],
    "coopctrl.integrators.modes": ["ModalAnalysis"],
}

#: Heavy contents, one per kind of field: a matrix, a long record, 1001 statuses, a long text.
HEAVY = [np.arange(441.0).reshape(21, 21), np.zeros((N, 18)), ["solved"] * N, "x" * 500, {f"k{i}": i for i in range(50)}]


def _assert_short(text: str) -> None:
    lines = text.split("\n")
    assert len(lines) <= MAX_LINES, text
    # a line may pass the width by one field's value at most (a field is never split)
    assert max(len(line) for line in lines) <= LINE_WIDTH + 70, text
    assert "'solved', 'solved'" not in text and "0., 0." not in text and "x" * 100 not in text


def _heavy_instance(cls):
    """An instance of ``cls`` (not built through its constructor) whose every field is heavy."""
    obj = object.__new__(cls)
    names = [f.name for f in dataclasses.fields(cls)] if dataclasses.is_dataclass(cls) else ["matrix", "record", "statuses"]
    for k, name in enumerate(names):
        object.__setattr__(obj, name, HEAVY[k % len(HEAVY)])
    return obj, names


@pytest.mark.parametrize("module, name", [(m, c) for m, cs in CLASSES.items() for c in cs])
def test_report_and_tuning_reprs_are_a_few_lines(module, name):
    cls = getattr(importlib.import_module(module), name)
    obj, names = _heavy_instance(cls)
    text = repr(obj)
    _assert_short(text)
    assert text.startswith(f"{name}(") and f"{names[0]}=" in text  # it still says what it is


def _result(**changes):
    from coopctrl.results import SimulationResult

    m, p = 2, 3
    t = np.linspace(0.0, 1.0, N)
    zeros = lambda *shape: np.zeros((N, *shape))  # noqa: E731
    fields = dict(scenario="planar_two_arm_lift", space="planar", t=t, x=zeros(18), tau=zeros(6), Y0=zeros(p),
                  Y0_nominal=zeros(p), F_measured=zeros(m, p), F_commanded=zeros(m, p), F_external=zeros(m, p),
                  F_internal=zeros(m, p), squeeze=zeros(1), squeeze_desired=[5.0], tau_max=np.full(6, 50.0),
                  qp_status=["solved"] * N, qp_iterations=np.ones(N), qp_solve_time_s=np.full(N, 1e-5),
                  integrator="rk4", step_s=1e-3, control_period_s=1e-3, duration_s=1.0, wall_time_s=0.25,
                  followers=[1])
    fields.update(changes)
    return SimulationResult(**fields)


def test_simulation_result_repr_names_scene_status_sizes_and_figures():
    text = repr(_result())
    _assert_short(text)
    for needle in ("scenario='planar_two_arm_lift'", "status='ok'", f"samples={N}", "arms=2", "state_size=18",
                   "position_error_rms_m=0", "qp_failures=0"):
        assert needle in text, text


def test_a_failed_run_shows_its_reason_cut_short():
    text = repr(_result(status="diverged", reason="diverged at t = 0.5 s: " + "because " * 40))
    _assert_short(text)
    assert "status='diverged'" in text and "reason='diverged at t = 0.5 s" in text


def test_loop_record_repr():
    from coopctrl.loop.record import LoopRecord

    rec = LoopRecord.empty(N, 18, 6, 2, 3, 2)
    rec.qp_status = ["solved"] * N
    text = repr(rec)
    _assert_short(text)
    assert text.startswith("LoopRecord(status='ok'") and f"ticks={N}" in text


def test_scenario_and_sweep_result_reprs():
    import coopctrl
    from coopctrl.sweep import SweepGrid, SweepResult

    scenario = coopctrl.load_scenario(None)
    text = repr(scenario)
    _assert_short(text)
    assert "name='default'" in text and "space='planar'" in text and "planar3r leader" in text
    grid = SweepGrid.parse(["simulation.seed=" + ",".join(str(i) for i in range(200))])
    rows = tuple({"run": i, "status": "ok" if i % 3 else "timeout", "reason": ""} for i in range(200))
    text = repr(SweepResult("default", None, grid, (), rows, 200))
    _assert_short(text)
    assert "runs=200" in text and "finished=200" in text and "failed=67" in text  # runs 0, 3, ..., 198


@pytest.mark.parametrize("value, text", [
    (np.array([1.0, 2.0]), "[1., 2.]"),
    (np.zeros((21, 21)), "<array 21x21 float64>"),
    (["solved"] * N, f"<list of {N} str>"),
    ((1, 2), "(1, 2)"),
    (0.123456789, "0.1235"),
    (True, "True"),
    (None, "None"),
])
def test_value_text(value, text):
    assert value_text(value) == text


def test_many_fields_are_counted_not_printed():
    @dataclasses.dataclass
    class Wide:
        __repr__ = compact_repr
        a0: float = 0.0

    obj = Wide()
    for i in range(1, 60):
        setattr(obj, f"a{i}", float(i))  # not fields: the repr lists the dataclass's fields only
    assert repr(obj) == "Wide(a0=0)"
    text = compact_repr(obj, [f"a{i}" for i in range(60)])
    assert len(text.split("\n")) == MAX_LINES and text.endswith("more)")
