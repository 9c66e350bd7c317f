"""What the package imports: nothing of it is compiled at run time, so no module of ``coopctrl`` or ``plants`` imports
numba (read from the sources with :mod:`ast`), and ``coopctrl run`` in a fresh process imports neither numba nor
scipy for the shipped carry and lift (scenes that need no scipy routine)."""

from __future__ import annotations

import ast
import json
import subprocess
import sys

import pytest

from test_cli import REPO


def _imports(path, package: str) -> list[int]:
    """The lines of ``path`` that import ``package`` (``import p``, ``import p.x``, ``from p... import``)."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    lines = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name.split(".")[0] == package for a in node.names):
            lines.append(node.lineno)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and (node.module or "").split(".")[0] == package:
            lines.append(node.lineno)
    return lines


def test_the_scan_sees_an_import_of_numba(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("import os\nfrom numba import njit\nimport numba.core\n", encoding="utf-8")
    assert _imports(probe, "numba") == [2, 3]


@pytest.mark.parametrize("package", ["coopctrl", "plants"])
def test_no_module_of_the_package_imports_numba(package):
    found = [f"{path.relative_to(REPO)}:{line}" for path in sorted((REPO / package).rglob("*.py"))
             for line in _imports(path, "numba")]
    assert not found, f"{package} imports numba:\n" + "\n".join(found)


_SCRIPT = """
import json, sys
from coopctrl.cli import main
code = main(["run", sys.argv[1], "-q"])
print(json.dumps({"code": code, "numba": "numba" in sys.modules, "scipy": "scipy" in sys.modules}))
"""


@pytest.mark.parametrize("scene", ["spatial_two_puma_carry", "planar_two_arm_lift"])
def test_a_run_imports_neither_numba_nor_scipy(scene, tmp_path):
    done = subprocess.run([sys.executable, "-c", _SCRIPT, scene], cwd=tmp_path, capture_output=True, text=True,
                          timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads(done.stdout.strip().splitlines()[-1])
    assert report == {"code": 0, "numba": False, "scipy": False}
