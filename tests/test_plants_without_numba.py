"""``import plants`` and every module of plants/ import no numba: the physics runs on the compiled core
(``plants._core``). The exceptions are the numba kernels that ``coopctrl/``'s numba code still calls, listed here
with their callers; each goes when its last caller does (and with it its line here)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import plants

#: Modules of plants/ that are numba kernels, kept for coopctrl/'s numba code: module -> its callers.
NUMBA_KERNELS = {
    "plants._numba_frames": "coopctrl/controllers/_kernels.py, load_distribution/, analysis/preflight_ik.py",
    "plants.arms._chain_kernels": "coopctrl/analysis/preflight_ik.py, mujoco/plant.py, plants.cooperative._spatial_kernel",
    "plants.arms._spatial_kernels": "coopctrl/analysis/preflight_ik.py",
    "plants.arms._planar_kernels": "coopctrl/analysis/preflight_ik.py, plants.cooperative._planar_kernel",
    "plants.elastic._planar_kernels": "plants.cooperative._planar_kernel",
    "plants.elastic._spatial_kernels": "plants.cooperative._spatial_kernel",
    "plants.cooperative._planar_kernel": "coopctrl/integrators/compiled.py, results/node_poses.py",
    "plants.cooperative._spatial_kernel": "coopctrl/integrators/compiled.py, results/node_poses.py",
    "plants.cooperative._linalg": "coopctrl/load_distribution/, the cooperative kernels",
    "plants.cooperative.workspaces": "CooperativePlant.workspace (coopctrl/'s numba integrators and their tests)",
}

_SCRIPT = """
import importlib, pkgutil, sys
import plants
skip = set(sys.argv[1].split(","))
names = sorted(m.name for m in pkgutil.walk_packages(plants.__path__, "plants.") if m.name not in skip)
for name in names:
    importlib.import_module(name)
print(len(names), sorted(m for m in sys.modules if m == "numba" or m.startswith("numba.")))
"""


def test_every_plants_module_but_the_kept_kernels_imports_no_numba():
    root = Path(plants.__file__).resolve().parent
    out = subprocess.run([sys.executable, "-c", _SCRIPT, ",".join(NUMBA_KERNELS)], capture_output=True, text=True,
                         timeout=300, cwd=root.parent)
    assert out.returncode == 0, out.stderr
    count, numba_modules = out.stdout.split(maxsplit=1)
    assert int(count) >= 40  # the walk found the package's modules
    assert numba_modules.strip() == "[]"


def test_each_kept_kernel_module_still_imports_numba():
    """A listed module that no longer imports numba (or no longer exists) leaves the list."""
    for name in NUMBA_KERNELS:
        out = subprocess.run([sys.executable, "-c", f"import sys, {name}; print('numba' in sys.modules)"],
                             capture_output=True, text=True, timeout=300)
        assert out.returncode == 0, (name, out.stderr)
        assert out.stdout.strip() == "True", name


def test_the_numba_names_asked_of_plants_frames_are_handed_out():
    """``from plants.frames import rotation_zyx_into`` (coopctrl's numba kernels) still works, and an unknown name
    still raises AttributeError."""
    out = subprocess.run([sys.executable, "-c", "import sys\nfrom plants import frames\n"
                          "assert 'numba' not in sys.modules\n"
                          "from plants.frames import rotation_zyx_into, body_rate_map_inverse\n"
                          "from plants.cooperative.loaded_state import body_rate_map_into\n"
                          "print(type(rotation_zyx_into).__name__, hasattr(frames, 'no_such_name'))"],
                         capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["CPUDispatcher", "False"]
