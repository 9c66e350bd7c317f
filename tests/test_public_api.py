"""No test reads a private member of the package (issue 18).

A test that reaches a name beginning with one underscore in ``coopctrl`` or ``plants`` pins an
implementation detail: the package may rename it at will, and the test then fails for a change no
user can see (or, patched, keeps testing a seam the product no longer uses). Every ``tests/*.py`` is
parsed with :mod:`ast` (nothing is imported or run) and these are refused:

* an import of a private module or name of the package: ``from plants.arms._chain_kernels import f``,
  ``from coopctrl.cli import _core``, ``import coopctrl.cli._core``;
* an attribute ``obj._name`` read or written on anything but the test's own ``self`` / ``cls`` and
  names imported from outside the package (``os._exit``): ``obj`` is a package module or an object
  the package returned (the scan cannot tell them apart, so an object built from the package, such as
  its argument parser, counts as the package's);
* a private name passed as a string to ``getattr``/``setattr``/``hasattr``/``delattr`` or to
  ``monkeypatch.setattr``/``delattr`` (``monkeypatch.setattr(module, "_seam", ...)``).

Dunder names (``__file__``, ``__name__``) are public. A test module's own private helpers (``_helper``
defined in a test, or imported from another test module) are the tests' business, not the package's.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
PACKAGES = ("coopctrl", "plants")

#: Why the plants core's tests may: each holds a function of plants._core (behind the public classes) to the physics
#: directly (gradients, the plant's equations, scipy), on inputs no public class builds (random tables, frames).
REASON_PLANTS_CORE = "tests the compiled core's functions (plants._core) behind the public classes directly"
#: Why coopctrl's core tests may read private names: coopctrl's kernels are the compiled core's alone, bound in the
#: private module coopctrl._core behind the public classes; these tests call the bindings directly to check each
#: kernel against an independent reference (its numpy statement, another solver, scipy, the plant's own methods).
REASON_COOPCTRL_CORE = ("checks a kernel of the compiled core (coopctrl._core) against an independent reference: "
                        "the kernel has no public entry of its own")

ALLOWED: dict[str, str] = {
    "test_docs_site.py": "argparse has no public list of a parser's options: the CLI reference's test reads parser._actions, as the reference's generator does",
    "test_core_adaptive.py": REASON_COOPCTRL_CORE,
    "test_core_arms.py": REASON_PLANTS_CORE,
    "test_core_control_laws.py": REASON_COOPCTRL_CORE,
    "test_core_cooperative.py": REASON_PLANTS_CORE,
    "test_core_cooperative_plant.py": REASON_PLANTS_CORE,
    "test_core_cooperative_spatial.py": REASON_PLANTS_CORE,
    "test_core_elastic.py": REASON_PLANTS_CORE,
    "test_core_frames.py": REASON_PLANTS_CORE,
    "test_core_goldfarb_idnani.py": REASON_COOPCTRL_CORE,
    "test_core_integrators.py": REASON_COOPCTRL_CORE,
    "test_core_node_poses.py": REASON_COOPCTRL_CORE,
    "test_core_planar_arm.py": REASON_PLANTS_CORE,
    "test_core_preflight_ik.py": REASON_COOPCTRL_CORE,
    "test_core_qp_assembly.py": REASON_COOPCTRL_CORE,
    "test_core_rigid_motion.py": REASON_PLANTS_CORE,
    "test_core_squeeze.py": REASON_COOPCTRL_CORE,
    "test_core_tick_checks.py": REASON_COOPCTRL_CORE,
    "test_controllers_laws.py": REASON_COOPCTRL_CORE,
    "test_goldfarb_idnani.py": REASON_COOPCTRL_CORE,
    "test_integrators_adaptive_plans.py": REASON_COOPCTRL_CORE,
    "test_integrators_compiled.py": REASON_COOPCTRL_CORE,
    "test_load_distribution_answer_check.py": REASON_COOPCTRL_CORE,
}

#: Calls whose second argument names an attribute.
_NAMING_CALLS = {"getattr", "setattr", "hasattr", "delattr"}


def _private(name: str) -> bool:
    """A name that begins with one underscore (a dunder name is public)."""
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _package_module(dotted: str | None) -> bool:
    return bool(dotted) and dotted.split(".")[0] in PACKAGES


def _private_path(dotted: str) -> bool:
    """A dotted path of the package through a private part: ``coopctrl.cli._core``."""
    return _package_module(dotted) and any(_private(part) for part in dotted.split("."))


def _own_object(node: ast.AST) -> bool:
    """``self`` or ``cls``: the test class's own members."""
    return isinstance(node, ast.Name) and node.id in ("self", "cls")


def _root(node: ast.AST) -> ast.AST:
    """The name an attribute chain starts from: ``a`` of ``a.b().c[0]._d``."""
    while isinstance(node, (ast.Attribute, ast.Call, ast.Subscript)):
        node = node.func if isinstance(node, ast.Call) else node.value
    return node


def _foreign_names(tree: ast.AST) -> set[str]:
    """Names the module binds by importing from outside the package (``os``, ``numpy``, another test
    module): ``os._exit`` is the standard library's business, not the package's."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if not _package_module(alias.name):
                    names.add(alias.asname or alias.name.split(".")[0])
        elif isinstance(node, ast.ImportFrom) and not (node.level == 0 and _package_module(node.module)):
            names.update(alias.asname or alias.name for alias in node.names)
    return names


def violations(source: str, filename: str = "<test>") -> list[str]:
    """Each private read of ``source`` as ``"line N: what"``."""
    tree = ast.parse(source, filename)
    foreign = _foreign_names(tree)
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if _private_path(alias.name):
                    found.append(f"line {node.lineno}: import {alias.name}")
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and _package_module(node.module):
            if _private_path(node.module):
                found.append(f"line {node.lineno}: from {node.module} import ...")
            for alias in node.names:
                if _private(alias.name):
                    found.append(f"line {node.lineno}: from {node.module} import {alias.name}")
        elif isinstance(node, ast.Attribute) and _private(node.attr) and not _own_object(node.value) and not (
                isinstance(_root(node.value), ast.Name) and _root(node.value).id in foreign):
            found.append(f"line {node.lineno}: .{node.attr}")
        elif isinstance(node, ast.Call) and len(node.args) >= 2:
            func = node.func
            named = (isinstance(func, ast.Name) and func.id in _NAMING_CALLS) or (
                isinstance(func, ast.Attribute) and func.attr in ("setattr", "delattr")
                and isinstance(func.value, ast.Name) and func.value.id == "monkeypatch")
            arg = node.args[1]
            if named and isinstance(arg, ast.Constant) and isinstance(arg.value, str) and _private(arg.value):
                found.append(f"line {node.lineno}: {ast.unparse(func)}(..., {arg.value!r})")
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "setattr":
            # monkeypatch.setattr("coopctrl.cli.run._seam", value): the target as one dotted string
            first = node.args[0] if node.args else None
            if isinstance(first, ast.Constant) and isinstance(first.value, str) and _private_path(first.value):
                found.append(f"line {node.lineno}: setattr({first.value!r}, ...)")
    return sorted(set(found), key=lambda s: int(s.split()[1].rstrip(":")))


def test_no_test_reads_a_private_member_of_the_package():
    report = []
    for path in sorted(TESTS.glob("*.py")):
        if path.name in ALLOWED:
            continue
        report += [f"tests/{path.name} {v}" for v in violations(path.read_text(encoding="utf-8"), str(path))]
    assert not report, ("tests read private members of the package (expose a public name, or test through "
                        "public behaviour):\n" + "\n".join(report))


def test_the_allow_list_names_existing_files_with_their_reason():
    for name, reason in ALLOWED.items():
        assert (TESTS / name).is_file(), f"{name} is allowed but does not exist: remove it from ALLOWED"
        assert reason.strip(), name


@pytest.mark.parametrize("source, what", [
    ("from plants.arms._chain_kernels import chain_arm_terms", "from plants.arms._chain_kernels import ..."),
    ("from coopctrl.cli import _core", "from coopctrl.cli import _core"),
    ("import coopctrl.cli._core as c", "import coopctrl.cli._core"),
    ("from coopctrl.cli.run import _simulate", "from coopctrl.cli.run import _simulate"),
    ("import coopctrl\ncoopctrl.cli.run._simulate_function()", ".line"),
    ("monkeypatch.setattr(cli.run, '_simulate_function', f)", "monkeypatch.setattr(..., '_simulate_function')"),
    ("monkeypatch.setattr('coopctrl.cli.run._seam', f)", "setattr('coopctrl.cli.run._seam', ...)"),
    ("getattr(loop, '_model')", "getattr(..., '_model')"),
    ("parser._actions", "._actions"),
])
def test_a_private_read_is_found(source, what):
    found = violations(source)
    assert len(found) == 1, (source, found)
    if what != ".line":
        assert found[0].endswith(what), (source, found)


@pytest.mark.parametrize("source", [
    "from plants.arms import chain_arm_terms",
    "import coopctrl.cli as cli\ncli.run.simulate_function",
    "from test_urdf_scenario import _dh_rows",  # another test module's private helper
    "def _helper():\n    pass\n_helper()",  # the test's own helper
    "class T:\n    def f(self):\n        return self._state",  # the test class's own member
    "import coopctrl\ncoopctrl.__file__",  # dunder names are public
    "monkeypatch.setattr(cli.run, 'simulate_function', f)",
    "import os\nos._exit(3)",  # the standard library's own (documented) name
])
def test_a_public_read_passes(source):
    assert violations(source) == []
