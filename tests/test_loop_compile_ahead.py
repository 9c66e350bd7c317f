"""coopctrl.loop.compile_ahead: a first run of a kind has its tick compiled by a second process while it
compiles the tick's stages, and then loads the tick from the cache."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
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


class _Child:
    """A stand-in for a compiling child (:class:`compile_ahead.Ahead`): it records its jobs and waits."""

    def __init__(self, jobs):
        self.jobs, self.waited = jobs, 0

    def wait(self, timeout_s=compile_ahead.WAIT_TIMEOUT_S):
        self.waited += 1
        return True

    def stop(self):
        pass


def test_a_child_started_before_preflight_is_the_one_the_run_waits_for(monkeypatch):
    """``compile_tick_ahead`` (``coopctrl run``, before pre-flight) starts the child of a cold kind; the run
    of that loop then waits for it rather than starting another, and runs as without it. The kind is made
    cold and the child a stand-in, so nothing compiles here."""
    import coopctrl
    from coopctrl.loop import compiled
    from coopctrl.scenario import build
    from coopctrl.simulator import closed_loop

    scenario = coopctrl.load_scenario(None, {"simulation.duration": 0.02})
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    expected = loop.run(x0, 0.02)
    children = []

    def start(jobs):
        children.append(_Child(jobs))
        return children[-1]

    monkeypatch.setattr(compile_ahead, "start", start)
    monkeypatch.setattr(startup, "compiles_here", lambda kind: True)
    assert compiled.compile_tick_ahead(loop) is True
    assert [name for name, _ in children[0].jobs] == ["run_ticks"]
    assert compiled.compile_tick_ahead(loop) is True  # the same tick again: that child still compiles it
    assert len(children) == 1
    record = loop.run(x0, 0.02)
    assert len(children) == 1 and children[0].waited == 1  # the run claimed it
    np.testing.assert_array_equal(record["x"], expected["x"])
    loop.run(x0, 0.02)  # a claimed child is not claimed twice: this run starts its own
    assert len(children) == 2 and children[1].jobs == children[0].jobs


def test_a_warm_kind_starts_no_child(monkeypatch):
    import coopctrl
    from coopctrl.loop import compiled
    from coopctrl.simulator import closed_loop

    monkeypatch.setattr(startup, "compiles_here", lambda kind: False)
    monkeypatch.setattr(compile_ahead, "start", lambda jobs: pytest.fail("a warm kind started a child"))
    assert compiled.compile_tick_ahead(closed_loop(coopctrl.load_scenario(None))) is False


def test_children_still_running_at_exit_are_stopped():
    """``stop_all`` (registered at exit) kills a child no run claimed, e.g. when pre-flight refused the task."""
    ahead = compile_ahead.start([])  # a child that reads its (empty) jobs after importing the kernel
    assert ahead.process is not None
    compile_ahead.stop_all()
    assert ahead.process.poll() is not None  # killed and reaped (or already done), never left behind
