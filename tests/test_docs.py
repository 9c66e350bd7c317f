"""The project's documentation is its own (issue 21): no tracked file names a path outside the
repository, and every ``docs/model.md s.N`` reference points at a section of docs/model.md that
holds what the reference cites with it (the book's equation and section numbers, ``[ours]``).
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
MODEL = REPO / "docs" / "model.md"

#: Paths outside the project. Each pattern is written so that this file's own source does not
#: match it (a character class where the literal text would be), so this file is checked too.
OUTSIDE = {
    "a parent directory's shared folder": re.compile(r"\.\./share[d]"),
    "an absolute path under the work tree": re.compile(r"/wor[k]/"),
    "a temporary-files path": re.compile(r"(?<![\w.])/tm[p]/"),
    "a home directory": re.compile(r"/hom[e]/"),
    "the physics reference outside docs/": re.compile(r"(?<!docs/)\bMODE[L]\.md"),
    "the performance notes outside docs/": re.compile(r"(?<!docs/)\bPERFORMANC[E]\.md"),
}

#: A reference to a section of docs/model.md: ``s.3``, ``§3``, ``section 3``, ``s.4-6``,
#: ``s.2 and s.4``, ``s.2-3``.
REFERENCE = re.compile(r"docs/model\.md`?,?\s*(?:#\s*)?(?:s\.|§|section\s+)\s*(\d+)(?:\s*-\s*(\d+))?"
                       r"(?:\s+and\s+(?:s\.|§)?\s*(\d+))?")
#: The same, written the other way round: ``section 5 of docs/model.md``.
REFERENCE_BEFORE = re.compile(r"section\s+(\d+)\s+of\s+`?docs/model\.md")
#: After a reference, the book's numbers it cites with it: equations 95..183, sections 4.N.
BOOK_NUMBER = re.compile(r"(?<![\d.])(4\.\d{1,2}|\d{2,3})(?![\d.]\d)")


def _tracked_text_files() -> list[Path]:
    out = subprocess.run(["git", "ls-files", "-z"], cwd=REPO, capture_output=True, check=True).stdout
    files = []
    for name in out.decode().split("\0"):
        path = REPO / name
        if not name or not path.is_file():
            continue
        data = path.read_bytes()
        if b"\0" in data[:8192]:  # binary (png)
            continue
        files.append(path)
    return files


@pytest.fixture(scope="module")
def files() -> dict[Path, str]:
    if not (REPO / ".git").exists():
        pytest.skip("not a git checkout: the tracked files are unknown")
    return {p: p.read_text(encoding="utf-8", errors="replace") for p in _tracked_text_files()}


def _sections() -> dict[int, str]:
    text = MODEL.read_text(encoding="utf-8")
    parts = re.split(r"^## (\d+)\. .*$", text, flags=re.M)
    return {int(parts[k]): parts[k + 1] for k in range(1, len(parts), 2)}


def test_no_file_names_a_path_outside_the_project(files):
    assert len(files) > 100  # the listing worked (README, code, scenes, tests)
    found = []
    for path, text in files.items():
        for what, pattern in OUTSIDE.items():
            for match in pattern.finditer(text):
                line = text.count("\n", 0, match.start()) + 1
                found.append(f"{path.relative_to(REPO)}:{line}: {what} ({match.group(0)!r})")
    assert not found, "\n".join(found)


def test_the_patterns_catch_what_they_are_for():
    # each pattern against a line it must catch and one it must let through
    caught = ["see ../share" "d/MODE" "L.md", "/wor" "k/shared/x", "written to /tm" "p/out", "/hom" "e/user",
              "(MODE" "L.md s.2)", "PERFORMANC" "E.md: runs agree"]
    passed = ["docs/model.md s.2", "docs/performance.md", "a tmp_path fixture", "#!/usr/bin/env bash"]
    for text in caught:
        assert any(p.search(text) for p in OUTSIDE.values()), text
    for text in passed:
        assert not any(p.search(text) for p in OUTSIDE.values()), text


def test_model_sections_are_numbered_in_order():
    sections = _sections()
    assert list(sections) == list(range(1, len(sections) + 1))
    assert len(sections) >= 6  # the numbering the code cites: 1 scene .. 6 control layer
    titles = re.findall(r"^## \d+\. (.*)$", MODEL.read_text(encoding="utf-8"), flags=re.M)
    assert titles[:6] == ["The scene", "Coordinates", "Elastic system", "Manipulators", "The cooperative system",
                          "Control layer"]


def _references(files):
    for path, text in files.items():
        if path == MODEL:
            continue
        for match in REFERENCE.finditer(text):
            first, last, other = match.group(1), match.group(2), match.group(3)
            cited = set(range(int(first), int(last or first) + 1)) | ({int(other)} if other else set())
            # what the reference cites with it: the rest of its clause (up to a closing parenthesis,
            # a semicolon or the end of the line)
            rest = re.split(r"[);\n]", text[match.end():match.end() + 80], maxsplit=1)[0]
            line = text.count("\n", 0, match.start()) + 1
            yield f"{path.relative_to(REPO)}:{line}", cited, rest
        for match in REFERENCE_BEFORE.finditer(text):
            line = text.count("\n", 0, match.start()) + 1
            yield f"{path.relative_to(REPO)}:{line}", {int(match.group(1))}, ""


def test_every_model_reference_names_a_section_that_holds_what_it_cites(files):
    sections = _sections()
    refs = list(_references(files))
    assert len(refs) > 50  # the code cites the model throughout
    problems = []
    for where, cited, rest in refs:
        missing = sorted(n for n in cited if n not in sections)
        if missing:
            problems.append(f"{where}: section {missing} does not exist")
            continue
        body = "\n".join(sections[n] for n in sorted(cited))
        numbers = [n for n in BOOK_NUMBER.findall(rest) if "." in n or 95 <= int(n) <= 183]
        for n in numbers:
            if not re.search(rf"(?<![\d.]){re.escape(n)}(?![\d]|\.\d)", body):
                problems.append(f"{where}: cites {n} with section {sorted(cited)}, which does not mention it")
        if "[ours]" in rest and "[ours]" not in body:
            problems.append(f"{where}: cites [ours] with section {sorted(cited)}, which marks nothing as ours")
    assert not problems, "\n".join(problems)
