"""coopctrl has no numba kernels: every tick, solve and kinematic pass of a run is the compiled core's
(``coopctrl._core``, coopctrl/core). No module of the package imports numba (read from the sources with
:mod:`ast`), and ``coopctrl run`` (pre-flight, the run, the outputs) in a fresh process leaves no compiled numba
function of a coopctrl module."""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys

import pytest

from test_cli import REPO


def _imports_numba(path) -> list[int]:
    """The lines of ``path`` that import numba (``import numba``, ``import numba.x``, ``from numba... import``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name.split(".")[0] == "numba" for a in node.names):
            lines.append(node.lineno)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == "numba":
            lines.append(node.lineno)
    return lines


def test_the_scan_sees_an_import_of_numba(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("import os\nfrom numba import njit\nimport numba.core\n", encoding="utf-8")
    assert _imports_numba(probe) == [2, 3]


def test_no_module_of_coopctrl_imports_numba():
    found = [f"{path.relative_to(REPO)}:{line}" for path in sorted((REPO / "coopctrl").rglob("*.py"))
             for line in _imports_numba(path)]
    assert not found, "coopctrl imports numba:\n" + "\n".join(found)


_SCRIPT = """
import gc, json, sys
from coopctrl.cli import main
code = main(["run", sys.argv[1], "--out", sys.argv[2], "--set", "simulation.duration=0.05"])
called = []
if "numba" in sys.modules:  # numba loaded by another package: no dispatcher may be coopctrl's
    from numba.core.registry import CPUDispatcher
    called = sorted({f"{d.py_func.__module__}.{d.py_func.__name__}" for d in gc.get_objects()
                     if isinstance(d, CPUDispatcher)})
print(json.dumps({"code": code, "called": called}))
"""


@pytest.mark.parametrize("scene", ["planar_two_arm_lift", "three_iiwa_tray"])  # planar; redundant spatial arms
def test_a_run_has_no_numba_function_of_coopctrl(scene, tmp_path):
    done = subprocess.run([sys.executable, "-c", _SCRIPT, scene, str(tmp_path / "out")], cwd=REPO,
                          capture_output=True, text=True, timeout=900, env=dict(os.environ))
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report["code"] in (0, None)
    assert (tmp_path / "out").is_dir()  # the outputs were written: the node poses ran
    assert [name for name in report["called"] if name.split(".")[0] == "coopctrl"] == []
