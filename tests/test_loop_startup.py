"""The kind of kernels a run needs, and whether the cache holds them (coopctrl.loop.startup)."""

from __future__ import annotations

import dataclasses

import pytest

from coopctrl.loop import startup
from coopctrl.loop.startup import KernelKind
from coopctrl.scenario import Scenario
from coopctrl.scenario.loader import load_scenario

from test_cli import REPO


def _index(directory, name):
    """A stand-in index file of the cache (only its name and presence are read)."""
    path = directory / "loop_0" / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(b"")
    return path


def test_a_kind_is_cold_until_its_start_up_is_recorded_and_again_when_a_listed_index_file_goes(tmp_path):
    planar = KernelKind("planar", "explicit")
    assert startup.is_cold(planar, tmp_path)
    startup.record_warm(planar, tmp_path)  # an empty cache (compiled in memory): nothing to list, no stamp
    assert startup.is_cold(planar, tmp_path)
    kept = _index(tmp_path, "kernel.run_ticks-525.py311.nbi")
    startup.record_warm(planar, tmp_path)
    assert not startup.is_cold(planar, tmp_path)
    # another kind shares the index file but has its own stamp: its variant may not be in it
    assert startup.is_cold(KernelKind("spatial", "explicit"), tmp_path)
    assert startup.is_cold(KernelKind("planar", "implicit"), tmp_path)
    kept.unlink()
    assert startup.is_cold(planar, tmp_path)


def test_started_records_the_kind_and_tells_the_listeners(tmp_path):
    kind = KernelKind("spatial", "implicit")
    _index(tmp_path, "integrate._sdirk_step-390.py311.nbi")
    heard = []
    with startup.listening(lambda k, s: heard.append((k, s))):
        startup.started(kind, 1.5, tmp_path)
    startup.started(kind, 2.5, tmp_path)  # no listener any more
    assert heard == [(kind, 1.5)]
    assert not startup.is_cold(kind, tmp_path)
    assert startup.stamp_path(kind, tmp_path).read_text().splitlines() == ["loop_0/integrate._sdirk_step-390.py311.nbi"]


def test_the_kind_of_a_scenario_is_its_space_and_integrator_family():
    assert startup.kind_of(Scenario()) == KernelKind("planar", "explicit")
    implicit = load_scenario(None, {"simulation.integrator": "implicit_midpoint"})
    assert startup.kind_of(implicit) == KernelKind("planar", "implicit")
    assert startup.family_of("euler") == startup.family_of("rk4") == "explicit"
    assert startup.family_of("implicit_euler") == "implicit"
    assert startup.family_of("rk23") == startup.family_of("rk45") == "embedded"
    assert startup.family_of("trbdf2") == "trbdf2"
    spatial = load_scenario(REPO / "scenarios" / "spatial_two_puma_carry.toml", {})
    assert startup.kind_of(spatial) == KernelKind("spatial", "explicit")
    assert startup.kind_of_run(True, "explicit") == startup.kind_of(spatial)


@pytest.mark.parametrize("field, value", [("space", "3d"), ("family", "rk4")])
def test_a_kind_names_its_bad_field(field, value):
    with pytest.raises(ValueError, match=f"{field} = '{value}' is invalid: expected one of"):
        dataclasses.replace(KernelKind("planar", "explicit"), **{field: value})


def test_family_of_refuses_a_non_name():
    with pytest.raises(TypeError, match="integrator = 3 is invalid: expected an integrator name"):
        startup.family_of(3)


def test_validating_a_scene_and_asking_if_its_kernels_are_compiled_imports_neither_numba_nor_scipy():
    """A bad input is refused, a first run announced and a sweep's runs validated before numba and scipy
    load (about 0.5 s of a process's start): the QP's classes and the loop's state are imported on first use."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from coopctrl.scenario import load_scenario\n"
        "from coopctrl.loop.startup import is_cold, kind_of\n"
        "from coopctrl.sweep.plan import plan_sweep\n"
        "from coopctrl.sweep.grid import SweepGrid\n"
        "s = load_scenario('spatial_two_puma_carry')\n"
        "is_cold(kind_of(s))\n"
        "plan_sweep('scenarios/spatial_two_puma_carry.toml', SweepGrid.parse(['simulation.seed=1,2']), {})\n"
        "print(sorted(m for m in sys.modules if m.split('.')[0] in ('numba', 'llvmlite', 'scipy')))\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, check=True)
    assert proc.stdout.strip() == "[]"
    import coopctrl.load_distribution as ld
    import coopctrl.loop as loop

    assert ld.LoadDistribution.__name__ == "LoadDistribution" and loop.LoopState.__name__ == "LoopState"
    assert {"LoadDistribution", "QPStats", "make_solver"} <= set(dir(ld))
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        ld.nothing  # noqa: B018 - the lazy lookup still refuses an unknown name


def test_a_kind_recorded_warm_in_this_process_is_not_read_from_the_disk_again(tmp_path, monkeypatch):
    """``compiles_here``: ``is_cold`` in this tree's cache until this process records the kind warm there;
    then no stamp is read (a sweep's later runs), even if the stamp goes."""
    monkeypatch.setattr(startup, "cache_directory", lambda: tmp_path)
    kind = KernelKind("spatial", "trbdf2")
    assert startup.compiles_here(kind)
    _index(tmp_path, "integrate._trbdf2_step-100.py311.nbi")
    startup.record_warm(kind, tmp_path)
    assert not startup.compiles_here(kind)
    startup.stamp_path(kind, tmp_path).unlink()
    assert startup.is_cold(kind, tmp_path)  # the disk says cold
    assert not startup.compiles_here(kind)  # this process already loaded it
