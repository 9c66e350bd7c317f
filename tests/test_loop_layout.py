"""Layout (issue 10, item 5): the loop imports nothing of ``coopctrl.analysis``, and the scenario layer plans
a loaded start without the simulator or the closed loop.

The imports are read from the source (every ``import`` statement, also those inside functions, which run
later), and followed through the project's own modules: what a module needs at any time, not only at
import time."""

from __future__ import annotations

import ast
import subprocess
import sys
from pathlib import Path

from test_cli import REPO

PACKAGE = REPO / "coopctrl"


def _module_file(name: str) -> Path | None:
    rel = Path(*name.split("."))
    for path in (REPO / rel.with_suffix(".py"), REPO / rel / "__init__.py"):
        if path.is_file():
            return path
    return None


def _imports(path: Path, top_level_only: bool = False) -> tuple[set[str], set[str]]:
    """``(modules, packages)``: the project modules (``coopctrl.*``) that ``path`` imports (with
    ``top_level_only``, only those imported when it is imported), and the packages on their way, which
    Python imports too (of those only their own top-level imports run)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    modules, packages = set(), set()
    for node in (tree.body if top_level_only else ast.walk(tree)):
        names = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
        for name in names:
            parts = name.split(".")
            if parts[0] != "coopctrl":
                continue
            if _module_file(name) is not None:
                modules.add(name)
            packages.update(".".join(parts[:k]) for k in range(1, len(parts)))
    return modules, {n for n in packages if _module_file(n) is not None} - modules


def closure(module: str) -> set[str]:
    """Every project module ``module`` reaches through its imports (itself included): all the imports of
    a module named in an import, the top-level ones of a package that is only on the way."""
    seen, todo = set(), [(module, False)]
    while todo:
        name, on_the_way = todo.pop()
        key = (name, on_the_way)
        if key in seen or (name, False) in seen:
            continue
        seen.add(key)
        modules, packages = _imports(_module_file(name), top_level_only=on_the_way)
        todo += [(m, False) for m in modules] + [(p, True) for p in packages]
    return {name for name, _ in seen}


def test_the_import_reader_finds_lazy_imports():
    """The reader is not blind: ``coopctrl.simulator`` imports the analysis' diagnosis inside a function."""
    assert "coopctrl.analysis.diagnosis" in closure("coopctrl.simulator")


def test_the_loop_does_not_reach_the_analysis_layer():
    loop_modules = ["coopctrl.closed_loop"] + [f"coopctrl.loop.{p.stem}" for p in (PACKAGE / "loop").glob("*.py")
                                                if p.stem != "__init__"]
    for module in loop_modules:
        reached = sorted(m for m in closure(module) if m.startswith("coopctrl.analysis") or m == "coopctrl.simulator")
        assert reached == [], f"{module} reaches {reached}"


def test_the_scenario_layer_does_not_reach_the_simulator_or_the_loop():
    for path in (PACKAGE / "scenario").glob("*.py"):
        module = "coopctrl.scenario" + ("" if path.stem == "__init__" else f".{path.stem}")
        reached = sorted(m for m in closure(module) if m in ("coopctrl.simulator", "coopctrl.closed_loop",
                                                             "coopctrl.wiring") or m.startswith("coopctrl.analysis"))
        assert reached == [], f"{module} reaches {reached}"


def test_a_loaded_start_is_planned_without_loading_the_simulator():
    """At run time too: the loaded start of the carry leaves the simulator and the closed loop unloaded."""
    code = ("import sys\nfrom coopctrl.scenario import load_scenario\n"
            f"s = load_scenario({str(REPO / 'scenarios' / 'spatial_two_puma_carry.toml')!r})\n"
            "assert s.simulation.start == 'loaded'\nx = s.initial_state()\n"
            "print(sorted(m for m in sys.modules if m in ('coopctrl.simulator', 'coopctrl.closed_loop', 'coopctrl.wiring')"
            " or m.startswith('coopctrl.analysis')))")
    proc = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=300,
                          env={**__import__("os").environ, "PYTHONPATH": str(REPO)})
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


#: The public methods of named tuples (their API begins with an underscore so as not to clash with field names).
_NAMEDTUPLE_API = {"_replace", "_fields", "_asdict", "_make"}


def _private_reads(path: Path) -> list[str]:
    """``obj._name`` in ``path`` on anything but ``self`` / ``cls`` (a named tuple's own API aside)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if (isinstance(node, ast.Attribute) and node.attr.startswith("_") and not node.attr.startswith("__")
                and node.attr not in _NAMEDTUPLE_API
                and not (isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"))):
            found.append(f"{path.name}:{node.lineno}: .{node.attr}")
    return found


def test_the_run_model_is_built_through_public_members(tmp_path):
    """Issue 42, item 2: the loop's model is built in one place (``coopctrl/loop/build.py``), driven by
    ``coopctrl/loop/run.py`` and, for the controller, ``coopctrl/controller/controller.py``, reading the loop's parts
    by their public names: none reads a private member of another object (the reader is checked on a line that
    does)."""
    probe = tmp_path / "probe.py"
    probe.write_text("def f(self, loop):\n    return self._x, loop._rho, loop.T._replace()\n", encoding="utf-8")
    assert _private_reads(probe) == ["probe.py:2: ._rho"]
    files = [PACKAGE / "loop" / "build.py", PACKAGE / "loop" / "run.py", PACKAGE / "controller" / "controller.py"]
    assert [hit for path in files for hit in _private_reads(path)] == []
