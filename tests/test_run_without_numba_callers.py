"""A run's Python side (pre-flight's inverse kinematics, the load distribution, the controllers' Python API, the
node poses) calls the C++ core, never the numba kernels those modules keep as the core tests' reference: after
``coopctrl run`` (pre-flight, the run, the outputs) in a fresh process, none of those kernels has a compiled or
loaded signature. (coopctrl.load_distribution.contact_model's torque model, called through
coopctrl.loop.qp_inputs, and the coopctrl.controllers._kernels it calls, are not listed: that caller is the loop's.)"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from test_cli import REPO

#: The modules whose numba kernels a run must not call.
MODULES = ("coopctrl.analysis.preflight_ik", "coopctrl.controllers.laws", "coopctrl.load_distribution.answer_check",
           "coopctrl.load_distribution.assembly", "coopctrl.load_distribution.goldfarb_idnani",
           "coopctrl.load_distribution.tensions", "coopctrl.results.node_poses")

_SCRIPT = """
import gc, json, sys
from numba.core.registry import CPUDispatcher
from coopctrl.cli import main
code = main(["run", sys.argv[1], "--out", sys.argv[2], "--set", "simulation.duration=0.05"])
called = sorted({f"{d.py_func.__module__}.{d.py_func.__name__}" for d in gc.get_objects()
                 if isinstance(d, CPUDispatcher) and d.signatures})
print(json.dumps({"code": code, "called": called}))
"""


@pytest.mark.parametrize("scene", ["planar_two_arm_lift", "three_iiwa_tray"])  # planar; redundant spatial arms
def test_a_run_calls_no_numba_kernel_of_the_switched_modules(scene, tmp_path):
    done = subprocess.run([sys.executable, "-c", _SCRIPT, scene, str(tmp_path / "out")], cwd=REPO,
                          capture_output=True, text=True, timeout=900, env=dict(os.environ))
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["code"] in (0, None)
    assert (tmp_path / "out").is_dir()  # the outputs were written: the node poses ran
    assert [name for name in report["called"] if name.rsplit(".", 1)[0] in MODULES] == []
