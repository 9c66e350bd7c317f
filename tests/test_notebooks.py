"""Every notebook in notebooks/ is stored without outputs and runs top to bottom without an error.

The notebooks run in a Jupyter kernel started with this interpreter (``sys.executable``): a
kernel spec written to a temporary ``JUPYTER_PATH`` for the test, so that a user's own
``python3`` kernel (another environment) can never be picked instead of the one under test.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

NOTEBOOKS = Path(__file__).resolve().parent.parent / "notebooks"
PATHS = sorted(NOTEBOOKS.glob("*.ipynb"))
KERNEL = "coopctrl-test-python"

#: Longest time one cell may take [s]: a hung kernel fails the test instead of blocking the suite.
CELL_TIMEOUT_S = 300


@pytest.fixture(scope="module")
def kernel(tmp_path_factory):
    """A kernel spec that runs ipykernel with this interpreter, first on JUPYTER_PATH."""
    root = tmp_path_factory.mktemp("jupyter")
    spec = root / "kernels" / KERNEL
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "coopctrl tests", "language": "python"}))
    mp = pytest.MonkeyPatch()
    mp.setenv("JUPYTER_PATH", str(root))
    yield KERNEL
    mp.undo()


def test_the_notebooks_are_there():
    names = {p.name for p in PATHS}
    assert {"tune_leader.ipynb", "tune_follower_force_loop.ipynb"} <= names


@pytest.mark.parametrize("path", PATHS, ids=[p.stem for p in PATHS])
def test_notebook_is_stored_without_outputs(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    for k, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            assert cell.outputs == [], f"{path.name}: cell {k} has stored outputs (clear them before committing)"
            assert cell.execution_count is None, f"{path.name}: cell {k} has an execution count"


@pytest.mark.parametrize("path", PATHS, ids=[p.stem for p in PATHS])
def test_notebook_runs_top_to_bottom(path, kernel):
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name=kernel,
                                     resources={"metadata": {"path": str(NOTEBOOKS)}})
    client.execute()  # raises CellExecutionError, naming the cell and the exception, on any error
    errors = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"]
    assert not errors
