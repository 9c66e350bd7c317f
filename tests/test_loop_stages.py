"""The compiled loop's stages called through pointers (coopctrl/loop/stages.py, kernel.tick_stages)."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from numba import njit, typeof, types
from numba.core.errors import NumbaExperimentalFeatureWarning

import coopctrl
from coopctrl.loop import kernel as K
from coopctrl.loop import stages
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop

ROOT = Path(__file__).resolve().parent.parent


def _scaled_sum(a, s):
    total = 0.0
    for i in range(a.shape[0]):
        total += s * a[i]
    return total


def test_a_stage_is_compiled_once_per_signature_and_computes_as_python():
    a = np.arange(5.0)
    first = stages.compile_stage(_scaled_sum, types.float64, a, types.float64)
    again = stages.compile_stage(_scaled_sum, types.float64, np.zeros(3), types.float64)
    assert again is first  # the same types: the same compiled stage
    other = stages.compile_stage(_scaled_sum, types.float64, np.zeros((2, 2))[0], types.int64)
    assert other is not first
    # called through its address from numba (as the kernel calls it): the Python function's result
    call = njit(lambda f, x, s: f(x, s))
    assert call(first, a, 2.0) == _scaled_sum(a, 2.0) == 20.0


def _twice(x):
    return 2.0 * x


def test_the_stages_by_name_are_typed_and_called_without_numbas_experimental_path():
    """A run's stages are a :class:`~coopctrl.loop.stages.TickStages`: numba types it field by field and the
    tick calls each by name, with every warning an error (no filter is installed anywhere). The same
    functions in a plain tuple go through numba's experimental unification of function types: its notice
    is what the named tuple avoids."""
    a = np.arange(5.0)
    f = stages.compile_stage(_scaled_sum, types.float64, a, types.float64)
    g = stages.compile_stage(_twice, types.float64, types.float64)
    named = stages.TickStages(advance=f, terms=g, qp_rows=f, qp_answer=g, control=f, energy=g, elastic_split=f)

    @njit
    def call(s, x):
        return s.advance(x, 2.0) + s.terms(3.0) + s.elastic_split(x, 1.0)

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert call(named, a) == 20.0 + 6.0 + 10.0
    with pytest.warns(NumbaExperimentalFeatureWarning, match="First-class function type feature is experimental"):
        typeof(tuple(named))


@pytest.mark.parametrize("passive, elastic", [(False, False), (True, False), (False, True)])
def test_energy_and_elastic_split_are_compiled_only_for_runs_that_use_them(passive, elastic, monkeypatch):
    """A run without an energy guard gets the stage that returns zeros (the plant's energy is never
    compiled for it), a pseudo-inverse split the elastic stage that does nothing; a passive run, whose
    energy is recorded, gets the plant's energy and an elastic split its inputs (``tests/test_loop.py``
    checks both against the Python plant and problem)."""
    compiled = []
    real = K.compile_stage

    def spy(function, *args, **kw):
        compiled.append(function)
        return real(function, *args, **kw)

    monkeypatch.setattr(K, "compile_stage", spy)
    overrides = {"simulation.duration": "0.02"}
    if passive:
        overrides["controllers.enabled"] = "false"
    if elastic:
        overrides["load_distribution.split"] = "elastic"
    scenario = coopctrl.load_scenario(ROOT / "scenarios" / "planar_two_arm_lift.toml", overrides)
    rec = closed_loop(scenario).run(build.initial_state(scenario), 0.02)
    assert rec["status"] == "ok"
    # the stages by their functions' names (the kernel's own, not part of the API)
    assert {f.__name__ for f in compiled} == {"_advance_explicit_stage", "_terms_stage", "_qp_rows", "_qp_answer", "_control",
                                              "_energy_stage" if passive else "_no_energy_stage",
                                              "_elastic_stage" if elastic else "_no_elastic_stage",
                                              "computed_torque_law"}  # the leader's law (the shipped one)
    assert np.all(np.isfinite(rec["energy"])) == passive  # recorded only by the passive run (NaN otherwise)


def test_coopctrl_run_prints_no_numba_notice_and_raises_none():
    """No numba notice reaches the user's terminal (stderr is empty), and numba's experimental-feature notice
    is never raised at all: the run passes with it made an error, in a fresh process (which types every
    argument afresh), and no file of the package filters it."""
    script = ("import sys, warnings; from numba.core.errors import NumbaExperimentalFeatureWarning as W; "
              "warnings.simplefilter('error', W); from coopctrl.cli import main; sys.exit(main(sys.argv[1:]))")
    for solver in ("compiled", "proxsuite"):
        result = subprocess.run([sys.executable, "-c", script, "run", "planar_two_arm_lift", "-q", "--set",
                                 "simulation.duration=0.05", "--set", f"load_distribution.solver={solver}"],
                                capture_output=True, text=True, timeout=600, cwd=ROOT)
        assert result.returncode == 0, result.stderr
        assert result.stderr == ""
    sources = [f for d in ("coopctrl", "plants") for f in (ROOT / d).rglob("*.py")]
    assert sources and not [f for f in sources if "NumbaExperimentalFeatureWarning" in f.read_text()]


def test_a_stages_type_before_it_is_compiled_is_the_type_of_the_compiled_stage():
    """``compile_stage(..., types_only=True)`` compiles nothing and gives what ``numba.typeof`` gives the
    compiled stage: what :mod:`coopctrl.loop.compile_ahead` compiles the tick for, in another process."""
    a = np.arange(5.0)
    ahead = stages.compile_stage(_scaled_sum, types.float64, a, types.float64, types_only=True)
    assert isinstance(ahead, types.Type)
    compiled = stages.compile_stage(_scaled_sum, types.float64, a, types.float64)
    assert typeof(compiled) == ahead
    other = stages.compile_stage(_scaled_sum, types.float64, a, types.int64, types_only=True)
    assert other != ahead  # another signature: another type
    named = stages.TickStages(advance=compiled, terms=compiled, qp_rows=compiled, qp_answer=compiled,
                              control=compiled, energy=compiled, elastic_split=compiled)
    typed = stages.TickStages(*([ahead] * 7))
    from coopctrl.loop import argument_types

    assert argument_types.signature_of((named, a, 0)) == argument_types.signature_of((typed, a, 0))
    assert argument_types.signature_of((typed, a, 0)) == (typeof(named), typeof(a), typeof(0))
