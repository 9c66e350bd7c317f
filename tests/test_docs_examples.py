"""Every example of README.md and docs/*.md runs, and prints what the page shows (issue 44).

Two kinds of code block are examples:

- ````` ```console `````: lines ``$ coopctrl ...`` are commands, run in this process
  (:func:`coopctrl.cli.main`) in a temporary folder; the lines after a command, up to the next one, are
  what it prints (stdout, then stderr). A line ``[exit N]`` states its exit code (0 when absent).
- ````` ```pycon `````: a Python session (``>>>`` and ``...`` prompts, as doctest reads them); each
  statement's output, or its exception (``Traceback ...`` then ``Type: message``), is compared with the
  lines after it. The blocks of one page share one namespace, in page order.

What a page shows is compared line by line: text as written (runs of spaces as one), numbers by value,
exactly as printed (a deterministic run is bit-identical on one machine: the printed digits are the run's);
``<time>`` stands for any number (wall times, real-time factors), ``<number>`` for any number the page
shows rounded elsewhere (a gain printed to 16 digits), ``<text>`` for any text within the line,
and a line ``...`` for any lines. Blank lines are ignored. Commands of ``bash`` blocks are not run, but each
``coopctrl`` command in them must parse with the program's parser. No other block may hold a prompt.
"""

from __future__ import annotations

import contextlib
import doctest
import io
import re
import shlex
import sys
import traceback
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PAGES = [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]

NUMBER = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
PLACEHOLDERS = {"<time>": NUMBER, "<number>": NUMBER, "<text>": ".*?"}
FIRST_RUN = re.compile(r"coopctrl: compiling .* for this machine")
FENCE = re.compile(r"^```(\w*)[^\n]*\n(.*?)^```", re.S | re.M)


@dataclass(frozen=True)
class Block:
    """One fenced code block: its page, first line (1-based, the fence), language and text."""

    page: Path
    line: int
    language: str
    text: str

    @property
    def where(self) -> str:
        shown = self.page.relative_to(REPO) if self.page.is_relative_to(REPO) else self.page.name
        return f"{shown}:{self.line}"


def blocks(text: str, page: Path) -> list[Block]:
    """The fenced code blocks of a Markdown text."""
    return [Block(page, text.count("\n", 0, m.start()) + 1, m.group(1), m.group(2)) for m in FENCE.finditer(text)]


# ---------------------------------------------------------------------------------------------------
# Comparing what a page shows with what ran


def _line_pattern(expected: str) -> tuple[re.Pattern, int]:
    """A regular expression for one shown line (numbers captured) and how many numbers it captures."""
    parts, count, pos = [], 0, 0
    token = re.compile("|".join([*(re.escape(p) for p in PLACEHOLDERS), r"\s+", rf"(?<![\w.]){NUMBER}(?![\w])"]))
    for m in token.finditer(expected):
        parts.append(re.escape(expected[pos:m.start()]))
        piece = m.group(0)
        if piece in PLACEHOLDERS:
            parts.append(PLACEHOLDERS[piece])
        elif piece.isspace():
            parts.append(r"\s+")
        else:
            parts.append(f"({NUMBER})")
            count += 1
        pos = m.end()
    parts.append(re.escape(expected[pos:]))
    return re.compile("".join(parts)), count


def _numbers_equal(shown: str, got: str) -> bool:
    if re.fullmatch(r"[-+]?\d+", shown):
        return shown.lstrip("+") == got.lstrip("+")  # a count, an arm, a joint: the same integer
    return float(shown) == float(got)  # the value as printed (`1.0e+05` and `100000.0` are one value)


def line_matches(expected: str, got: str) -> bool:
    """``got`` is the line ``expected`` shows (placeholders, numbers by value, spaces as one)."""
    expected, got = " ".join(expected.split()), " ".join(got.split())
    pattern, _ = _line_pattern(expected)
    m = pattern.fullmatch(got)
    if not m:
        return False
    shown = re.findall(rf"(?<![\w.]){NUMBER}(?![\w])", re.sub("|".join(map(re.escape, PLACEHOLDERS)), " ", expected))
    return all(_numbers_equal(s, g) for s, g in zip(shown, m.groups()))


def output_matches(expected: list[str], got: list[str]) -> bool:
    """The lines ``got`` are the lines ``expected`` shows; an expected line ``...`` stands for any lines."""
    expected = [e for e in expected if e.strip()]
    got = [g for g in got if g.strip()]

    def match(i: int, j: int) -> bool:
        if i == len(expected):
            return j == len(got)
        if expected[i].strip() == "...":
            return any(match(i + 1, k) for k in range(j, len(got) + 1))
        return j < len(got) and line_matches(expected[i], got[j]) and match(i + 1, j + 1)

    return match(0, 0)


def _report(where: str, what: str, expected: list[str], got: list[str]) -> str:
    return (f"{where}: {what}\n--- the page shows:\n" + "\n".join(expected) + "\n--- it printed:\n" + "\n".join(got))


# ---------------------------------------------------------------------------------------------------
# Running the examples


def console_commands(block: Block) -> list[tuple[str, list[str], int]]:
    """``(command, shown output lines, expected exit code)`` for each ``$`` line of a console block."""
    out: list[tuple[str, list[str], int]] = []
    for line in block.text.splitlines():
        if line.startswith("$ "):
            out.append((line[2:].strip(), [], 0))
        elif not out:
            raise AssertionError(f"{block.where}: a console block starts with a `$ ` command line")
        elif m := re.fullmatch(r"\[exit (\d+)\]", line.strip()):
            out[-1] = (out[-1][0], out[-1][1], int(m.group(1)))
        else:
            out[-1][1].append(line)
    return out


def run_console(block: Block, capsys) -> int:
    """Run a console block's commands; returns how many ran."""
    from coopctrl import cli

    commands = console_commands(block)
    for command, shown, code in commands:
        words = shlex.split(command)
        assert words[0] in ("coopctrl", ".venv/bin/coopctrl"), f"{block.where}: only `coopctrl ...` commands run here: {command!r}"
        capsys.readouterr()
        got_code = cli.main(words[1:])
        captured = capsys.readouterr()
        # a first run of a kind says on stderr that it compiles (getting-started.md shows that line)
        lines = captured.out.splitlines() + [ln for ln in captured.err.splitlines() if not FIRST_RUN.match(ln)]
        assert got_code == code, _report(block.where, f"`{command}` exited {got_code}, the page says {code}", shown, lines)
        assert output_matches(shown, lines), _report(block.where, f"`{command}`", shown, lines)
    return len(commands)


def run_pycon(block: Block, namespace: dict) -> int:
    """Run a pycon block in ``namespace``; returns how many statements ran."""
    examples = doctest.DocTestParser().get_examples(block.text)
    assert examples, f"{block.where}: a pycon block without a `>>>` statement"
    for example in examples:
        where = f"{block.where}+{example.lineno + 1}"
        buffer = io.StringIO()
        raised = None
        with contextlib.redirect_stdout(buffer):
            try:
                exec(compile(example.source, where, "single"), namespace)  # noqa: S102 - the page's own example
            except Exception as error:  # noqa: BLE001 - compared with what the page shows
                raised = error
        got = buffer.getvalue().splitlines()
        if example.exc_msg is not None:
            assert raised is not None, _report(where, f"{example.source.strip()!r} raised nothing", [example.exc_msg], got)
            last = traceback.format_exception_only(type(raised), raised)[-1].strip()
            assert output_matches(example.exc_msg.splitlines(), [last]), _report(where, "the exception", [example.exc_msg], [last])
            continue
        if raised is not None:
            raise AssertionError(f"{where}: {example.source.strip()!r} raised {raised!r}") from raised
        shown = example.want.splitlines()
        assert output_matches(shown, got), _report(where, repr(example.source.strip()), shown, got)
    return len(examples)


def examples_of(text: str, page: Path) -> int:
    """How many examples a page holds (commands and Python statements)."""
    n = 0
    for block in blocks(text, page):
        if block.language == "console":
            n += len(console_commands(block))
        elif block.language == "pycon":
            n += len(doctest.DocTestParser().get_examples(block.text))
    return n


def _example_groups() -> list[tuple[Path, int | None]]:
    """What one test runs: each console block alone (``(page, its line)``), and a page's pycon blocks
    together (``(page, None)``: they share a namespace), so that the examples spread over the workers."""
    groups = []
    for page in PAGES:
        found = blocks(page.read_text(encoding="utf-8"), page)
        groups += [(page, b.line) for b in found if b.language == "console"]
        if any(b.language == "pycon" for b in found):
            groups.append((page, None))
    return groups


def run_group(page: Path, line: int | None, text: str, capsys, tmp_path: Path, monkeypatch) -> int:
    """Run the console block of ``page`` at ``line``, or (``line`` None) every pycon block of the page."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(sys, "argv", ["coopctrl"])
    namespace: dict = {"__name__": "__main__"}
    count = 0
    for block in blocks(text, page):
        if line is not None and block.language == "console" and block.line == line:
            count += run_console(block, capsys)
        elif line is None and block.language == "pycon":
            count += run_pycon(block, namespace)
    return count


@pytest.mark.parametrize(("page", "line"), _example_groups(),
                         ids=lambda v: str(v.relative_to(REPO)) if isinstance(v, Path) else ("python" if v is None else str(v)))
def test_page_examples_print_what_the_page_shows(page, line, capsys, tmp_path, monkeypatch):
    text = page.read_text(encoding="utf-8")
    assert run_group(page, line, text, capsys, tmp_path, monkeypatch) > 0


def test_the_examples_are_counted():
    counts = {str(p.relative_to(REPO)): examples_of(p.read_text(encoding="utf-8"), p) for p in PAGES}
    assert counts["README.md"] >= 2 and sum(counts.values()) >= 40, counts
    print("examples per page:", counts, "total", sum(counts.values()))


def test_no_other_block_holds_a_prompt():
    found = []
    for page in PAGES:
        for block in blocks(page.read_text(encoding="utf-8"), page):
            if block.language not in ("console", "pycon") and re.search(r"^(\$ |>>> )", block.text, re.M):
                found.append(f"{block.where}: a `{block.language or 'plain'}` block with a prompt: make it console or pycon")
            if block.language == "pycon" and "<fill>" in block.text or block.language == "console" and "<fill>" in block.text:
                found.append(f"{block.where}: an example still shows <fill>")
    assert not found, "\n".join(found)


def test_every_shown_command_parses():
    """The ``coopctrl`` commands of bash blocks, which are not run, are ones the program accepts."""
    from coopctrl.cli import build_parser

    parser = build_parser()
    checked = 0
    for page in PAGES:
        for block in blocks(page.read_text(encoding="utf-8"), page):
            if block.language != "bash":
                continue
            for line in block.text.replace("\\\n", " ").splitlines():
                words = shlex.split(line, comments=True)
                if "coopctrl" in (words[0].rsplit("/", 1)[-1] if words else ""):
                    if words[0].endswith("coopctrl") and len(words) > 1 and "&&" not in words:
                        parser.parse_args(words[1:])
                        checked += 1
    assert checked >= 10


# ---------------------------------------------------------------------------------------------------
# The check fails when a page changes (on copies of pages, with cheap examples)


def test_a_changed_number_in_a_python_example_fails(capsys, tmp_path, monkeypatch):
    page = REPO / "docs" / "robots.md"
    text = page.read_text(encoding="utf-8")
    shown = "[0.6565 0.1694 0.4129 1.9264 0.1073 1.2901]"
    assert shown in text
    copy = tmp_path / "robots.md"
    copy.write_text(text.replace(shown, shown.replace("0.4129", "0.4128")), encoding="utf-8")
    assert run_group(page, None, text, capsys, tmp_path, monkeypatch) > 0  # the page as it is passes
    with pytest.raises(AssertionError, match="0.4128"):
        run_group(copy, None, copy.read_text(encoding="utf-8"), capsys, tmp_path, monkeypatch)


def test_a_changed_number_in_a_command_example_fails(capsys, tmp_path, monkeypatch):
    page = REPO / "docs" / "reliability.md"
    text = page.read_text(encoding="utf-8")
    shown = "<= 0.1 [m or rad]"
    assert shown in text
    copy = tmp_path / "reliability.md"
    copy.write_text(text.replace(shown, "<= 0.2 [m or rad]"), encoding="utf-8")
    line = next(b.line for b in blocks(text, page) if b.language == "console" and shown in b.text)
    assert run_group(page, line, text, capsys, tmp_path, monkeypatch) > 0  # the page as it is passes
    with pytest.raises(AssertionError, match=re.escape("<= 0.2")):
        run_group(copy, line, copy.read_text(encoding="utf-8"), capsys, tmp_path, monkeypatch)


@pytest.mark.parametrize(("expected", "got", "same"), [
    ("wall time  <time> s", "wall time   0.0411 s", True),
    ("status  ok", "status  diverged", False),
    ("max |tau| / tau_max  0.2523", "max |tau| / tau_max   0.2523", True),
    ("max |tau| / tau_max  0.2523", "max |tau| / tau_max   0.2524", False),
    ("QP solves  2501", "QP solves  2502", False),
    ("(50000.0, 20000.0)", "(50000.0, 20000.0)", True),
    ("x 1e-06 m", "x 1e-6 m", True),
    ("error: <text>/a.toml: bad", "error: /x/y/a.toml: bad", True),
])
def test_line_matching(expected, got, same):
    assert line_matches(expected, got) is same


def test_ellipsis_stands_for_any_lines():
    assert output_matches(["a", "...", "d"], ["a", "b", "c", "d"])
    assert output_matches(["a", "...", "b"], ["a", "b"])
    assert not output_matches(["a", "...", "d"], ["a", "b", "c"])
    assert not output_matches(["a"], ["a", "b"])
