"""The documentation site (issue 44): it builds strictly, its references are complete, its pages hold no diary.

``mkdocs build --strict`` (broken links, missing pages, unresolved API references fail it) runs into a
temporary folder; the built pages are then checked: the API reference has an entry for every public name
(``coopctrl.__all__``, ``plants.__all__`` and the ``__all__`` of ``plants``' subpackages), the CLI
reference every subcommand and option of the parser. No page keeps a diary (times of day, load averages,
dated entries). tests/test_readme.py checks the README, tests/test_docs_examples.py runs every example.
"""

from __future__ import annotations

import html
import importlib
import importlib.util
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text(encoding="utf-8")
DOCS = REPO / "docs"
PAGES = [REPO / "README.md", *sorted(DOCS.glob("*.md")), *sorted((DOCS / "data").glob("*.md"))]

#: The modules whose ``__all__`` is the public API the reference must cover.
PUBLIC = ("coopctrl", "plants", "plants.arms", "plants.elastic", "plants.cooperative")

needs_mkdocs = pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None or importlib.util.find_spec("mkdocstrings") is None,
                                  reason="mkdocs and mkdocstrings are not installed: pip install -e '.[docs]'")


def build_site(tmp_path: Path) -> Path:
    """The site built strictly from the checkout into a temporary folder."""
    out = tmp_path / "site"
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    proc = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
                          cwd=REPO, capture_output=True, text=True, timeout=300, env=env)
    assert proc.returncode == 0, proc.stderr[-4000:]
    assert not re.search(r"^WARNING", proc.stderr, re.M), proc.stderr[-4000:]
    return out


def _ids(page: Path) -> set[str]:
    return set(re.findall(r'\bid="([^"]+)"', page.read_text(encoding="utf-8")))


@needs_mkdocs
def test_the_site_builds_strictly_with_complete_references(tmp_path):
    """One strict build (a broken link, a missing picture or an unresolved API reference fails it), then
    its pages: every page of docs/ in the nav, every public name in the API reference, every subcommand
    and option in the CLI reference."""
    site = build_site(tmp_path)
    check_every_page(site)
    check_api_reference(site)
    check_cli_reference(site)


@needs_mkdocs
def test_the_build_is_strict_and_the_benchmark_table_is_included():
    """The configuration makes every warning (a broken link or anchor, a page missing from the nav, an
    unresolved reference) fail the build, and the benchmarks page includes the file run_all.py writes."""
    import yaml

    class _Loader(yaml.SafeLoader):  # mkdocs.yml may hold !!python tags; none are needed here
        pass

    config = yaml.load((REPO / "mkdocs.yml").read_text(encoding="utf-8"), Loader=_Loader)
    assert config["strict"] is True
    assert set(config["validation"].values()) == {"warn"}  # warnings, which strict makes errors
    assert '--8<-- "data/benchmarks.md"' in (DOCS / "benchmarks.md").read_text(encoding="utf-8")
    data = (DOCS / "data" / "benchmarks.md").read_text(encoding="utf-8")
    for field in ("| command |", "| date (UTC) |", "| machine |", "| versions |", "| medians of |", "| ratio |"):
        assert field in data, field


def check_every_page(site: Path) -> None:
    nav_pages = re.findall(r":\s*([\w-]+\.md)\s*$", (REPO / "mkdocs.yml").read_text(encoding="utf-8"), re.M)
    assert len(nav_pages) >= 16
    for name in nav_pages:
        assert (DOCS / name).is_file(), name
        built = site / ("index.html" if name == "index.md" else f"{name[:-3]}/index.html")
        assert built.is_file(), name
    assert "compiled us/tick" in (site / "benchmarks" / "index.html").read_text(encoding="utf-8")  # the table
    assert not [p.name for p in DOCS.glob("*.md") if p.name not in nav_pages], "a page is missing from the nav"


def _public_names() -> list[tuple[str, object]]:
    names = []
    for module_name in PUBLIC:
        module = importlib.import_module(module_name)
        names += [(f"{module_name}.{name}", getattr(module, name)) for name in module.__all__]
    return names


def check_api_reference(site: Path) -> None:
    ids = _ids(site / "api" / "index.html")
    missing = []
    for public, obj in _public_names():
        # documented under its public path, or where it is defined (the same object)
        defined = f"{getattr(obj, '__module__', '')}.{getattr(obj, '__qualname__', '')}"
        short = public.rsplit(".", 1)[1]
        if public not in ids and defined not in ids and not any(i.endswith(f".{short}") and _same_object(i, obj) for i in ids):
            missing.append(public)
    assert len(_public_names()) >= 30
    assert not missing, f"not in docs/api.md: {missing}"


def _same_object(path: str, obj) -> bool:
    module, _, name = path.rpartition(".")
    try:
        return getattr(importlib.import_module(module), name) is obj
    except (ImportError, AttributeError, ValueError):
        return False


def check_cli_reference(site: Path) -> None:
    import argparse

    from coopctrl.cli import build_parser

    text = html.unescape(re.sub(r"<[^>]+>", "", (site / "cli" / "index.html").read_text(encoding="utf-8")))
    subcommands = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices
    assert len(subcommands) >= 9
    missing = []
    for name, parser in subcommands.items():
        section = text.split(f"coopctrl {name}", 1)
        if len(section) < 2:
            missing.append(name)
            continue
        for action in parser._actions:
            for option in action.option_strings:
                if option not in section[1]:
                    missing.append(f"{name} {option}")
    assert not missing, missing


def test_the_cli_hook_renders_every_option():
    """The hook alone (no mkdocs needed): each option of each subcommand is in its rendered section."""
    sys.path.insert(0, str(DOCS / "hooks"))
    try:
        import cli_reference
    finally:
        sys.path.pop(0)
    from coopctrl.cli import build_parser

    text = cli_reference.render()
    sections = dict(re.findall(r"^## `coopctrl ([\w-]+)`\n(.*?)(?=^## |\Z)", text, re.S | re.M))
    subs = cli_reference.subparsers(build_parser())
    assert set(sections) == set(subs)
    for name, parser in subs.items():
        for action in parser._actions:
            for option in action.option_strings:
                assert f"`{option}`" in sections[name], (name, option)


def test_the_roles_hook_shows_code_as_sphinx_does():
    sys.path.insert(0, str(DOCS / "hooks"))
    try:
        import sphinx_roles
    finally:
        sys.path.pop(0)
    html_in = ":class:<code>~coopctrl.results.SimulationResult</code> from :func:<code>coopctrl.load_scenario</code>"
    assert sphinx_roles.plain(html_in) == "<code>SimulationResult</code> from <code>coopctrl.load_scenario</code>"
    assert sphinx_roles.plain("a <code>:x:</code> stays") == "a <code>:x:</code> stays"


# ---------------------------------------------------------------------------------------------------
# Pages without a diary

#: A time of day (``13:31``, ``09:36 UTC``), a load average, or a dated entry (``2026-12-03``, ``on 2026-12-01``).
DIARY = {
    "a time of day": re.compile(r"(?<![\d:])(?:[01]\d|2[0-3]):[0-5]\d(?::[0-5]\d)?(?![\d:])"),
    "a load average": re.compile(r"\bload (?:average|of)\b|\bload \d", re.I),
    "a date": re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b"),
    "a before/after entry": re.compile(r"\b(?:before|after)\b[^.\n]{0,40}\b20\d\d\b|\bthe tree (?:before|after)\b", re.I),
}


def test_no_page_holds_a_diary():
    found = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for what, pattern in DIARY.items():
            if page.parent.name == "data" and what == "a date":
                continue  # the benchmark table states the date it was measured on
            for m in pattern.finditer(text):
                line = text.count("\n", 0, m.start()) + 1
                found.append(f"{page.relative_to(REPO)}:{line}: {what} ({m.group(0)!r})")
    assert not found, "\n".join(found)


def test_the_diary_patterns_catch_what_they_are_for():
    caught = ["Rerun on 2026-12-03 at 13:31 UTC", "load average 0.9", "(load 1.2 to 1.4)", "the tree before (b47fd74)"]
    passed = ["a 1 ms tick", "ratio 7.8x", "t = 0.016 s", "rk4 at h = T/2", "pitch 90 deg", "`x[0:3]`"]
    for text in caught:
        assert any(p.search(text) for p in DIARY.values()), text
    for text in passed:
        assert not any(p.search(text) for p in DIARY.values()), text


def test_the_grid_counts_the_page_states():
    from coopctrl.analysis.tradeoff import parse_integrators
    from coopctrl.integrators import ERROR_CONTROLLED, INTEGRATORS

    words = {3: "three", 4: "four", 5: "five", 6: "six", 7: "seven"}
    text = " ".join((DOCS / "speed-accuracy.md").read_text(encoding="utf-8").split())
    assert f"all {words[len(INTEGRATORS)]} fixed-step integrators" in text
    assert f"all {words[len(ERROR_CONTROLLED)]} error-controlled integrators" in text
    assert len(parse_integrators(None)) == len(INTEGRATORS) + len(ERROR_CONTROLLED)


def test_every_benchmark_is_listed_and_answers_help():
    listed = set(re.findall(r"python (benchmarks/\w+\.py)", (DOCS / "benchmarks.md").read_text(encoding="utf-8")))
    scripts = {f"benchmarks/{p.name}" for p in (REPO / "benchmarks").glob("*.py") if not p.name.startswith("_")}
    assert listed == scripts
    procs = {s: subprocess.Popen([sys.executable, s, "--help"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                 text=True, cwd=REPO) for s in sorted(scripts)}
    for script, popen in procs.items():
        out, err = popen.communicate(timeout=120)
        assert popen.returncode == 0, (script, err)
        assert "--quick" in out, script
