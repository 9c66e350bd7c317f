"""plants.numba_cache: numba's cache keyed on every kernel source. numba keys a cached function on
its own file, so a changed callee in another file used to run stale machine code; here a callee is
edited in a copy of the package and the next run must use the change."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from plants import numba_cache

REPO = Path(__file__).resolve().parent.parent

#: The offset element's energy from its numba kernel (plants/elastic/_spatial_kernels.py; ElasticSystem itself
#: calls the compiled core), which calls the rotation of plants/frames.py, a callee in another file.
_SCRIPT = """
import sys
# an editable install's import finder maps the project's packages to the checkout: this run imports the copy's
sys.meta_path[:] = [f for f in sys.meta_path if type(f).__name__ != "ScikitBuildRedirectingFinder"]
import numpy as np
from plants.elastic import ElasticSystem, Interconnection, Node, _spatial_kernels
Y_ref = np.array([[0, 0, 0, 0, 0, 0], [0.3, 0, 0, 0, 0, 0.0]])
el = ElasticSystem("spatial", [Node(1.0, (1, 1, 1)), Node(1.0, (1, 1, 1))],
                   [Interconnection((0, 1), 1000.0, torsion=10.0, element="offset")], Y_ref, gravity=0.0)
Y = Y_ref.copy()
Y[0, 3:] = (0.1, 0.2, 0.3)
Y[1, :3] += 0.01
print(repr(_spatial_kernels.elastic_edges(Y, el.edge_index, el.edge_params, np.zeros_like(Y))[0]))
"""


def _copy(tmp_path: Path) -> Path:
    """A copy of the packages, with the compiled core's modules as installed (built from plants/core, coopctrl/core)."""
    import coopctrl._core
    import plants._core

    top = tmp_path / "src"
    for name in ("plants", "coopctrl"):
        shutil.copytree(REPO / name, top / name, ignore=shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc"))
    for module, package in ((plants._core, "plants"), (coopctrl._core, "coopctrl")):
        shutil.copy2(module.__file__, top / package / Path(module.__file__).name)
    return top


def _energy(top: Path, cache: Path) -> float:
    env = {**os.environ, "PYTHONPATH": str(top), "NUMBA_CACHE_DIR": str(cache)}
    out = subprocess.run([sys.executable, "-c", _SCRIPT], env=env, cwd=top, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    return float(out.stdout.strip().splitlines()[-1])


def test_the_key_follows_the_kernel_sources_and_nothing_else(tmp_path):
    top = _copy(tmp_path)
    key = numba_cache.cache_key(top)
    assert numba_cache.cache_key(top) == key
    plain = top / "coopctrl" / "scenario" / "schema.py"  # pure Python: no numba in it
    assert "numba" not in plain.read_text() or "no numpy" in plain.read_text()
    plain.write_text(plain.read_text() + "\n# an edit outside the kernels\n")
    assert numba_cache.cache_key(top) == key
    callee = top / "plants" / "frames.py"
    callee.write_text(callee.read_text() + "\n# an edit of a kernel source\n")
    assert numba_cache.cache_key(top) != key


def test_an_edited_callee_in_another_file_is_used_by_the_next_run(tmp_path):
    top, cache = _copy(tmp_path), tmp_path / "cache"
    before = _energy(top, cache)
    assert _energy(top, cache) == before  # the second run loads the cache: same machine code, same number
    callee = top / "plants" / "frames.py"
    text = callee.read_text()
    assert text.count("    R[2, 0] = -sth\n") >= 1
    callee.write_text(text.replace("    R[2, 0] = -sth\n", "    R[2, 0] = -2.0 * sth\n"))  # a wrong rotation
    after = _energy(top, cache)
    assert after != before
    assert len(list(cache.glob("coopctrl-*"))) == 2  # one directory per source digest


def test_a_child_process_keeps_the_keyed_directory(tmp_path, monkeypatch):
    base = tmp_path / "numba"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(base))
    directory = numba_cache.keyed_directory(REPO)
    assert directory.parent == base and directory.name.startswith("coopctrl-")
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(directory))  # as configure() leaves it for a child process
    assert numba_cache.keyed_directory(REPO) == directory  # NUMBA_CACHE_DIR now names it: not nested again
    assert not base.exists()  # the path alone: nothing created
