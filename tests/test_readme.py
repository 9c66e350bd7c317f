"""The README tells the truth (issue 14): its commands are run and their printed claims checked.

Only the commands listed here are checked, each asserted to appear verbatim in README.md (so a
README edit that changes one fails here until this list follows). Sections this file does not
list (stability, URDF robots, reliability, ...) are free to change without breaking it.
Commands run as ``python -m coopctrl`` / ``python benchmarks/...`` for ``.venv/bin/...``, with
their outputs redirected into a temporary directory.
"""

from __future__ import annotations

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

import coopctrl
from coopctrl.integrators import INTEGRATORS

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text(encoding="utf-8")

RUN = ".venv/bin/coopctrl run scenarios/spatial_two_puma_carry.toml --out out/carry"
LIST = ".venv/bin/coopctrl list"
CHECK = ".venv/bin/coopctrl check scenarios/heavy_payload_torque_limits.toml"
SHOW = ".venv/bin/coopctrl show spatial_two_puma_carry --set simulation.duration=1"
VIEW = ".venv/bin/coopctrl view out/carry"
RANGE = ".venv/bin/coopctrl check planar_two_arm_lift --set 'springs[0].stiffness=1.7976931348623157e308'"
INSTALL = "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/coopctrl run"
#: Summary lines whose values are timings (they vary from run to run).
TIMINGS = ("wall time", "real-time factor", "QP solve time median")
#: Relative tolerance on the README's printed figures: they are shown to 4 significant digits, and a
#: different CPU or library version may move the last one.
RTOL = 2e-3


def _argv(command: str, out: Path) -> list[str]:
    import shlex

    words = [w.replace("out/carry", str(out)) for w in shlex.split(command)]
    assert words[0] == ".venv/bin/coopctrl"
    return [sys.executable, "-m", "coopctrl", *words[1:]]


def _run(command: str, out: Path) -> subprocess.CompletedProcess:
    assert command in README, f"README.md no longer shows {command!r}: update tests/test_readme.py with it"
    return subprocess.run(_argv(command, out), capture_output=True, text=True, cwd=REPO, timeout=600)


@pytest.fixture(scope="module")
def carry(tmp_path_factory):
    out = tmp_path_factory.mktemp("readme") / "carry"
    return out, _run(RUN, out)


def _printed_block(after: str) -> list[str]:
    start = README.index(after)
    block = README[start:].split("```", 2)[1]
    return [ln for ln in block.splitlines()[1:] if ln.strip()]


def _split(line: str) -> tuple[str, str]:
    m = re.match(r"^(.*?\S)\s{2,}(\S.*)$", line)
    return (m.group(1), m.group(2)) if m else (line, "")


def _same(expected: str, got: str) -> bool:
    num = r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?"
    e_nums, g_nums = re.findall(num, expected), re.findall(num, got)
    if re.sub(num, "#", expected) != re.sub(num, "#", got) or len(e_nums) != len(g_nums):
        return False
    return all(abs(float(a) - float(b)) <= RTOL * abs(float(a)) for a, b in zip(e_nums, g_nums))


def test_run_prints_what_the_readme_shows(carry):
    out, proc = carry
    assert proc.returncode == 0, proc.stderr
    got = dict(_split(ln) for ln in proc.stdout.splitlines() if ln.strip())
    expected = _printed_block(f"`{RUN.removeprefix('.venv/bin/')}` prints:")
    assert len(expected) >= 10
    for line in expected:
        key, value = _split(line)
        if key.startswith("outputs written to"):
            assert f"outputs written to {out}" in proc.stdout
            continue
        assert key in got, f"README shows {key!r}, the run does not print it"
        if key not in TIMINGS:
            assert _same(value, got[key]), f"{key}: README {value!r}, run {got[key]!r}"


def test_run_writes_the_files_the_readme_lists(carry):
    out, _ = carry
    listed = re.findall(r"`([\w.]+\.(?:npz|csv|json|toml|html|png))`", README.split("prints:", 1)[1].split("### 3-D replay")[0])
    assert {"result.npz", "result.csv", "summary.json", "scenario.toml", "replay.html", "object_pose.png",
            "contact_forces.png", "joint_torques.png", "qp_solve_times.png"} <= set(listed)
    for name in listed:
        assert (out / name).is_file(), name
    header = (out / "result.csv").read_text().splitlines()[0].split(",")
    for column in re.findall(r"`(\w+ \[[^\]]+\])`", README.split("### Data", 1)[1].split("##", 1)[0]):
        assert column in header, column


def test_view_rewrites_the_replay(carry):
    out, _ = carry
    (out / "replay.html").unlink()
    proc = _run(VIEW, out)
    assert proc.returncode == 0, proc.stderr
    assert (out / "replay.html").stat().st_size > 500_000  # three.js is inlined: no network needed


def test_list_check_and_show(tmp_path):
    proc = _run(LIST, tmp_path)
    assert proc.returncode == 0
    names = {ln.split()[0] for ln in proc.stdout.splitlines() if ln.strip()}
    assert {p.stem for p in (REPO / "scenarios").glob("*.toml")} <= names
    proc = _run(CHECK, tmp_path)
    assert proc.returncode == 0 and proc.stdout.startswith("ok: heavy_payload_torque_limits"), proc.stderr
    proc = _run(SHOW, tmp_path)
    assert proc.returncode == 0, proc.stderr
    shown = tmp_path / "shown.toml"
    shown.write_text(proc.stdout)
    assert coopctrl.load_scenario(shown) == coopctrl.load_scenario(
        REPO / "scenarios" / "spatial_two_puma_carry.toml", {"simulation.duration": 1})
    assert tomllib.loads(proc.stdout)["simulation"]["duration"] == 1.0


def test_out_of_range_value_is_refused_as_quoted(tmp_path):
    proc = _run(RANGE, tmp_path)
    assert proc.returncode == 2 and proc.stdout == ""
    quoted = re.search(r"prints `coopctrl: error: \.\.\.(/planar_two_arm_lift\.toml: .*?)` \(one line\)", README, re.S)
    assert quoted
    assert proc.stderr.strip().endswith(" ".join(quoted.group(1).split()))
    assert len(proc.stderr.strip().splitlines()) == 1


def test_tradeoff_default_integrator_count():
    words = {3: "three", 4: "four", 5: "five", 6: "six", 7: "seven"}
    assert f"default: all {words[len(INTEGRATORS)]} integrators" in README
    from coopctrl.analysis.tradeoff import parse_integrators

    assert len(parse_integrators(None)) == len(INTEGRATORS)


def test_benchmarks_accept_quick_and_help_runs_nothing():
    listed = re.findall(r"\.venv/bin/python (benchmarks/bench_\w+\.py)", README)
    assert sorted(set(listed)) == sorted(f"benchmarks/{p.name}" for p in (REPO / "benchmarks").glob("bench_*.py"))
    assert "Each accepts\n`--quick`" in README or "Each accepts `--quick`" in README
    procs = {bench: subprocess.Popen([sys.executable, bench, "--help"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                     text=True, cwd=REPO) for bench in sorted(set(listed))}
    for bench, popen in procs.items():
        stdout, stderr = popen.communicate(timeout=120)
        proc = subprocess.CompletedProcess(popen.args, popen.returncode, stdout, stderr)
        assert proc.returncode == 0, (bench, proc.stderr)
        assert "--quick" in proc.stdout, bench
        assert "command:" not in proc.stdout, bench  # every benchmark prints its command first when it runs


def test_no_real_network_address():
    assert not re.search(r"\b\d{1,3}\.\d{1,3}\.\d{1,3}\.\d{1,3}\b", README)
    assert "tcp://scheduler.example:8786" in README


def test_user_install_needs_no_test_extras():
    assert INSTALL in README
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    base = " ".join(project["dependencies"]).lower()
    assert "pin" not in re.findall(r"[a-z_-]+", base) and "roboticstoolbox" not in base
    code = ("import sys, coopctrl; from coopctrl.cli import main; "
            "assert main(['run', '--quiet', '--set', 'simulation.duration=0.05']) == 0; "
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('pinocchio', 'roboticstoolbox', 'pytest')))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"  # a run imports no test oracle


def test_gains_print_as_set_text():
    from coopctrl.tuning import Gains

    assert "paste after `coopctrl run SCENARIO`" in README
    assert str(Gains(follower_force_kp=0.7).as_set_options()) == "--set controllers.followers.force_kp=0.7"


def test_python_example_runs():
    blocks = re.findall(r"```python\n(.*?)```", README, re.S)
    block = next(b for b in blocks if "result.figures()" in b)
    code = block + "\nassert list(df.attrs['units'])[0] == 't' and len(figures) == 4\n"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO, timeout=300)
    assert proc.returncode == 0, proc.stderr
