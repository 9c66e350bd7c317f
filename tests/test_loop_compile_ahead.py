"""coopctrl.loop.compile_ahead: a first run of a kind has its tick compiled by a second process while it
compiles the tick's stages, and then loads the tick from the cache."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from coopctrl.loop import compile_ahead, startup

REPO = Path(__file__).resolve().parent.parent

#: A first run of the default scene (planar, rk4) that prints its status and how numba got ``run_ticks``
#: in this process: loaded from the cache (hits) or compiled here (misses).
_SCRIPT = """
import coopctrl
from coopctrl.loop import kernel as K
from coopctrl.simulator import simulate
result = simulate(coopctrl.load_scenario(None, {"simulation.duration": 0.01}))
stats = K.run_ticks.stats
print(result.status, sum(stats.cache_hits.values()), sum(stats.cache_misses.values()))
"""


def test_only_the_kernels_functions_are_compiled_ahead():
    with pytest.raises(ValueError, match="function 'rhs_kernel' is invalid: expected one of"):
        compile_ahead.start([("rhs_kernel", ())])


def test_a_child_that_never_started_reports_failure():
    assert compile_ahead.Ahead(None).wait() is False


def test_the_first_run_of_a_kind_loads_the_tick_a_second_process_compiled(tmp_path):
    """The suite's kernel cache copied without its stamps (so the kind is cold, and the run starts the
    child) and without ``run_ticks`` (numba's files of it, named after the function): the stages load from
    the copy, the tick is compiled by the child, and the run then finds it in the cache: a hit, no miss.
    Without the child the run would compile it itself (a miss). Run alone, with the suite's cache still
    empty, this test compiles the stages as well."""
    source = startup.cache_directory()
    target = tmp_path / source.name
    if source.is_dir():
        shutil.copytree(source, target, ignore=shutil.ignore_patterns(startup.STAMP_FOLDER, "kernel.run_ticks-*"))
    assert not list(target.rglob("kernel.run_ticks-*"))
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path),
           "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    out = subprocess.run([sys.executable, "-c", _SCRIPT], capture_output=True, text=True, env=env, cwd=REPO,
                         timeout=1200)
    assert out.returncode == 0, out.stderr
    status, hits, misses = out.stdout.split()[-3:]
    assert status == "ok"
    assert (int(hits), int(misses)) == (1, 0)
    assert list(target.rglob("kernel.run_ticks-*.nbi"))  # the child's compile, in the run's cache
