"""The compiled loop's stages called through pointers (coopctrl/loop/stages.py, kernel.tick_stages)."""

from __future__ import annotations

import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
from numba import njit, types
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
    with stages.pointers_in_use():
        assert call(first, a, 2.0) == _scaled_sum(a, 2.0) == 20.0


def test_pointers_in_use_silences_only_numbas_first_class_function_notice():
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        with stages.pointers_in_use():
            warnings.warn("First-class function type feature is experimental", NumbaExperimentalFeatureWarning)
            warnings.warn("another notice", NumbaExperimentalFeatureWarning)
            warnings.warn("First-class function type feature is experimental", UserWarning)
    assert [str(w.message) for w in seen] == ["another notice", "First-class function type feature is experimental"]


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
    assert {f.__name__ for f in compiled} == {"_advance_stage", "_terms_stage", "_qp_rows", "_qp_answer", "_control",
                                              "_energy_stage" if passive else "_no_energy_stage",
                                              "_elastic_stage" if elastic else "_no_elastic_stage",
                                              "computed_torque_law"}  # the leader's law (the shipped one)
    assert np.all(np.isfinite(rec["energy"])) == passive  # recorded only by the passive run (NaN otherwise)


def test_coopctrl_run_prints_no_numba_notice():
    """The first-class function notice never reaches the user's terminal (stderr is empty)."""
    result = subprocess.run([sys.executable, "-m", "coopctrl", "run", "planar_two_arm_lift", "-q", "--set",
                             "simulation.duration=0.05"], capture_output=True, text=True, timeout=600, cwd=ROOT)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
