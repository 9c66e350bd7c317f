"""The README is a landing page (issues 14, 44): short, its commands the ones CI runs, its links alive,
its speed figures the benchmarks' own.

Its examples (the first scene, the Python snippet) run in tests/test_docs_examples.py with the docs'.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text(encoding="utf-8")
DOCS = REPO / "docs"

INSTALL = "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && .venv/bin/coopctrl run"
TESTS = ".venv/bin/python -m pytest -q"
USER_INSTALL = "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/coopctrl run"




def test_readme_is_a_landing_page():
    assert len(README) <= 12_000, len(README)
    assert README.count("\n## ") <= 8


def test_readme_keeps_the_two_commands_that_ci_runs():
    ci = (REPO / ".ci" / "run").read_text(encoding="utf-8")
    first_block = re.search(r"```bash\n(.*?)```", README, re.S).group(1).splitlines()
    assert first_block == [INSTALL, TESTS]
    assert f"{INSTALL.replace('pip install', 'pip install -q')}\n" in ci and f"\n{TESTS}\n" in ci


def test_readme_links_to_pages_that_exist():
    links = re.findall(r"\]\((docs/[^)#]+)", README)
    assert len(links) >= 15
    for link in links:
        assert (REPO / link).is_file(), link
    for page in DOCS.glob("*.md"):
        if page.name != "index.md":
            assert f"docs/{page.name}" in README, f"README does not say where {page.name} is"


def test_readme_headline_is_the_benchmark_data_files():
    """The README's speed sentence is written by benchmarks/run_all.py from the figures of its data file."""
    data = (DOCS / "data" / "benchmarks.md").read_text(encoding="utf-8")
    sentence = re.search(r"<!-- benchmark-headline -->\n(.*?)\n<!-- /benchmark-headline -->", README, re.S).group(1)
    rt, us, ratio = re.search(r"\*\*([\d.]+)x real time\*\* \(([\d.]+) us per 1 ms tick\), ([\d.]+)x faster", sentence).groups()
    row = re.search(r"^\| `spatial_two_puma_carry` \| ok \| \d+ \| ([\d.]+) \| ([\d.]+) \| ([\d.]+) \|", data, re.M)
    assert row, "docs/data/benchmarks.md has no row for the carry: run python benchmarks/run_all.py --quick"
    assert (us, rt) == (row.group(1), row.group(2))
    assert float(ratio) == pytest.approx(float(row.group(3)) / float(row.group(1)), abs=0.06)


def test_user_install_needs_no_test_extras():
    """The install without extras that the README offers runs a scene without any test oracle."""
    assert USER_INSTALL in README
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    base = " ".join(project["dependencies"]).lower()
    assert "pin" not in re.findall(r"[a-z_-]+", base) and "roboticstoolbox" not in base and "mkdocs" not in base
    code = ("import sys, coopctrl; from coopctrl.cli import main; "
            "assert main(['run', '--quiet', '--set', 'simulation.duration=0.05']) == 0; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('pinocchio', 'roboticstoolbox', 'pytest', 'mkdocs')))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"  # a run imports no test oracle and no docs tool


def test_no_real_network_address():
    text = README + "".join(p.read_text(encoding="utf-8") for p in DOCS.glob("*.md"))
    assert not re.search(r"\b\d{1,3}\.\d{1,3}\.\d{1,3}\.\d{1,3}\b", text)


def test_the_readme_shows_the_mujoco_table_the_benchmark_wrote():
    """The README's table of the shipped scenes on both plants is the first table of docs/data/mujoco_plants.md,
    which benchmarks/mujoco_plants.py writes (never typed by hand)."""
    data = (REPO / "docs" / "data" / "mujoco_plants.md").read_text(encoding="utf-8").split("\n")
    table = "\n".join(line for line in data if line.startswith("|") and "signal" not in line and "largest" not in line)
    first = table.split("\n")[:7]  # header, rule, the five scenes
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    begin = "<!-- mujoco_plants:begin (benchmarks/mujoco_plants.py) -->\n"
    assert begin + "\n".join(first) + "\n<!-- mujoco_plants:end -->" in readme
