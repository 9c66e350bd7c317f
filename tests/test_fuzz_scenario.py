"""Seeded fuzz of hostile scene input through the command line (issue 22): hostile strings in every string
field of a scene (and in its keys, and in --set values), and hostile scene files (devices, FIFOs,
folders, oversized, deeply nested, random bytes, bad UTF-8).

Every case must be refused as bad input: exit 2, one line on stderr starting ``coopctrl: error:``, no
traceback, no raw control character reaching the terminal, and no simulation or pre-flight started
(both are replaced by functions that fail the test). The CLI runs in-process (``cli.main``), so each case
costs milliseconds; a SIGALRM bounds each case so that a hang fails the test instead of stopping the suite.
"""

from __future__ import annotations

import functools
import os
import random
import re
import signal
import stat

import pytest

from coopctrl import cli
from coopctrl.io import dumps_toml
from coopctrl.scenario import Scenario
from coopctrl.scenario.scene_file import MAX_SCENE_BYTES
from coopctrl.scenario.text import MAX_DEPTH, MAX_TEXT

#: Wall-clock bound of one case [s]: bad input is refused in milliseconds; the bound only turns a hang
#: into a failure (it is no timing assertion: a loaded machine stays far below it).
CASE_BOUND_S = 20.0
#: Fuzz draws per string field (seeded).
DRAWS = 4
#: Characters a terminal acts on or that are not text: C0 (but tab), DEL, C1, lone surrogates.
RAW_CONTROL = re.compile(r"[\x00-\x08\x0a-\x1f\x7f-\x9f\ud800-\udfff]")


class Hang(BaseException):
    """A case went past its bound (a BaseException: the command line's handlers do not catch it)."""


class Started(BaseException):
    """Bad input reached the simulation or the pre-flight (a BaseException: nothing catches it)."""


@pytest.fixture(autouse=True)
def no_simulation(monkeypatch):
    """Fail any case that gets as far as building the closed loop or running pre-flight."""
    import coopctrl.analysis.preflight as preflight
    import coopctrl.simulator as simulator

    def refuse(*args, **kwargs):
        raise Started("bad input reached the simulation")

    monkeypatch.setattr(simulator, "simulate", refuse)
    monkeypatch.setattr(simulator, "closed_loop", refuse)
    monkeypatch.setattr(preflight, "preflight", refuse)


@pytest.fixture(autouse=True)
def one_parser(monkeypatch):
    """Build the argument parser once for the module's cases (building it costs tens of ms, parsing
    microseconds; argparse makes a fresh namespace, with copied defaults, on every parse)."""
    monkeypatch.setattr(cli, "build_parser", _ONE_PARSER)


_ONE_PARSER = functools.lru_cache(maxsize=1)(cli.build_parser)


@pytest.fixture
def refused(capsys):
    """``refused(args)``: run the CLI in-process within CASE_BOUND_S and check the refusal; returns the line."""
    def expire(signum, frame):
        raise Hang(f"case still running after {CASE_BOUND_S} s")

    previous = signal.signal(signal.SIGALRM, expire)

    def run(args, *needles):
        capsys.readouterr()
        signal.setitimer(signal.ITIMER_REAL, CASE_BOUND_S)
        try:
            code = cli.main([str(a) for a in args])
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
        out, err = capsys.readouterr()
        case = f"{args!r}: exit {code}, stderr {err!r}"
        assert code == 2, case
        assert out == "", case
        lines = err.splitlines()
        assert len(lines) == 1 and lines[0].startswith("coopctrl: error: "), case
        assert "Traceback" not in err and "internal error" not in err, case
        assert RAW_CONTROL.search(err.rstrip("\n")) is None, case
        for needle in needles:
            assert needle in lines[0], case
        return lines[0]

    yield run
    signal.signal(signal.SIGALRM, previous)


def hostile_strings(rng: random.Random, count: int) -> list[str]:
    """Strings with at least one refused character (C0, DEL, C1, or, where ``surrogates``, a lone
    surrogate) at a random place among printable text, plus the classic terminal attacks."""
    fixed = ["\x1b]0;pwned\x07", "\x1b[2J\x1b[H", "ok\x00nul", "\x9b31m", "tab\tand\x7fdel", "line\nbreak", "cr\rx"]
    bad = [chr(c) for c in (*range(0, 9), *range(10, 32), 0x7F, *range(0x80, 0xA0))]
    out = list(fixed)
    for _ in range(count):
        text = "".join(rng.choice("abcXYZ_- ./\u00e9\u4e2d") for _ in range(rng.randint(0, 12)))
        at = rng.randint(0, len(text))
        out.append(text[:at] + rng.choice(bad) + text[at:])
    return out


def scene_dict() -> dict:
    """A valid URDF-free spatial scene as a TOML dict (planar default scene, every section written)."""
    return Scenario().to_dict()


#: The string fields of a scene file, as (dotted path, setter on the TOML dict).
def _set(path):
    def setter(data, value):
        node = data
        parts = re.findall(r"[^.\[\]]+", path)
        for part in parts[:-1]:
            node = node[int(part)] if part.isdigit() else node.setdefault(part, {})
        last = parts[-1]
        if last.isdigit():
            node[int(last)] = value
        else:
            node[last] = value
    return setter


STRING_FIELDS = (
    "name", "description", "scene.space", "scene.unloaded_state", "arms[0].model", "arms[1].role",
    "arms[0].urdf", "arms[0].base_link", "arms[0].tip_link", "springs[0].element", "springs[0].damping_form",
    "load_distribution.split", "load_distribution.solver", "simulation.integrator", "simulation.start",
)


@pytest.mark.parametrize("field", STRING_FIELDS)
def test_hostile_strings_in_every_string_field_of_a_file(field, tmp_path, refused):
    """Written into the file as TOML escapes (a raw control character is a TOML syntax error, also
    refused): the loader sees the character itself."""
    rng = random.Random(f"file:{field}")
    for k, text in enumerate(hostile_strings(rng, DRAWS)):
        data = scene_dict()
        _set(field)(data, text)
        path = tmp_path / f"case{k}.toml"
        # TOML escapes for DEL and C1, which dumps_toml writes raw (a TOML syntax error, refused as well)
        toml = re.sub(r"[\x7f-\x9f]", lambda m: f"\\u{ord(m.group()):04x}", dumps_toml(data))
        path.write_text(toml, encoding="utf-8")
        line = refused(["check", path])
        assert field.split("[")[0].split(".")[0] in line  # the field (or its section) is named


@pytest.mark.parametrize("field", STRING_FIELDS)
def test_hostile_strings_in_every_string_field_by_set(field, refused):
    """Through --set, including lone surrogates (what Python makes of bytes that are not UTF-8 in argv)."""
    rng = random.Random(f"set:{field}")
    cases = hostile_strings(rng, DRAWS) + ["\udcff", "x\ud800y", "\udce9t\udce9"]
    for text in cases:
        refused(["check", "--set", f"{field}={text}"])


def test_lone_surrogate_in_the_name_is_refused_at_load(refused):
    line = refused(["check", "--set", "name=caf\udce9"], "name", "U+DCE9")
    assert "\\udce9" in line  # shown escaped


@pytest.mark.parametrize("key", ["\x1b]0;x\x07", "bad\u0085key", "name\x00"])
def test_hostile_keys(key, tmp_path, refused):
    path = tmp_path / "key.toml"
    escaped = key.encode("unicode_escape").decode("ascii").replace("\\x", "\\u00")
    path.write_text(dumps_toml(scene_dict()) + f'\n[extra]\n"{escaped}" = 1\n', encoding="utf-8")
    refused(["check", path], "extra.")


def test_hostile_set_paths(refused):
    rng = random.Random(7)
    for text in hostile_strings(rng, DRAWS):
        refused(["check", "--set", f"simulation.{text}=1"])


def test_overlong_strings(tmp_path, refused):
    data = scene_dict()
    data["description"] = "x" * (MAX_TEXT + 1)
    path = tmp_path / "long.toml"
    path.write_text(dumps_toml(data))
    line = refused(["check", path], "description", f"at most {MAX_TEXT} characters")
    assert len(line) < 1000  # the value is shown cut, not whole


# ---------------------------------------------------------------------- hostile files
@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom", "/dev/null"])
def test_devices_are_refused_without_reading(device, refused):
    if not os.path.exists(device):
        pytest.skip(f"{device} does not exist here")
    refused(["check", device], "character device, not a regular file")
    refused(["run", device], "not a regular file")


def test_fifo_is_refused_without_blocking(tmp_path, refused):
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)  # nobody writes: opening it for reading would block
    assert stat.S_ISFIFO(os.stat(fifo).st_mode)
    refused(["check", fifo], "FIFO")
    refused(["sweep", fifo, "--grid", "simulation.seed=0,1"], "FIFO")


def test_directory_is_refused(tmp_path, refused):
    refused(["check", tmp_path], "a directory, not a regular file")


def test_oversized_file_is_refused_before_reading(tmp_path, refused):
    path = tmp_path / "huge.toml"
    with open(path, "wb") as handle:  # sparse: its size costs no disk and no reading
        handle.truncate(4 * 1024**3)
    refused(["check", path], f"at most {MAX_SCENE_BYTES} bytes")


@pytest.mark.parametrize("depth", [MAX_DEPTH + 2, 5000, 200_000])
@pytest.mark.parametrize("kind", ["array", "table"])
def test_deep_nesting_is_one_line(kind, depth, tmp_path, refused):
    """Nested arrays or inline tables: beyond the parser's recursion (RecursionError inside tomllib) or
    beyond MAX_DEPTH after parsing; both one line, exit 2."""
    opened, closed = ("[" * depth, "]" * depth) if kind == "array" else ("{a=" * depth, "1" + "}" * depth)
    text = dumps_toml(scene_dict()) + f"\n[extra]\nx = {opened}{'1' if kind == 'array' else ''}{closed}\n"
    assert len(text) <= MAX_SCENE_BYTES  # within the size bound: the nesting is the point here
    path = tmp_path / "deep.toml"
    path.write_text(text)
    refused(["check", path])


def test_deep_nesting_in_a_set_value(refused):
    refused(["check", "--set", "description=" + "[" * 5000 + "]" * 5000], "description")


def test_random_bytes_and_bad_utf8(tmp_path, refused):
    rng = random.Random(22)
    cases = [b"", b"\xff\xfe\x00\x00", b'name = "\xc3"\n', b"\x00" * 64, bytes(rng.getrandbits(8) for _ in range(4096))]
    valid = dumps_toml(scene_dict()).encode()
    for _ in range(8):  # a valid scene with a few random bytes flipped
        data = bytearray(valid)
        for _ in range(rng.randint(1, 4)):
            data[rng.randrange(len(data))] = rng.getrandbits(8)
        cases.append(bytes(data))
    refusals = 0
    for k, data in enumerate(cases):
        path = tmp_path / f"random{k}.toml"
        path.write_bytes(data)
        try:
            refused(["check", path])
            refusals += 1
        except Started:
            pass  # a flip that left the scene valid reaches pre-flight, as it should
    assert refusals >= 5  # at least the five broken files above
