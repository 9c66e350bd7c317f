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
TIMINGS = ("wall time", "real-time factor", "startup (compile or load)", "QP solve time median")
#: Relative tolerance on the README's printed figures: they are shown to 4 significant digits, and a
#: different CPU or library version may move the last one. (On one machine the deterministic runs are
#: bit-identical; a figure printed with fewer digits may also move by one unit of its last digit, see
#: :func:`_last_digit`.)
RTOL = 2e-3


def _last_digit(text: str) -> float:
    """One unit of the last printed digit of a decimal number as written (``"0.189"`` -> 1e-3,
    ``"3.799e-05"`` -> 1e-8): a rounding flip on another machine moves it by that."""
    mantissa, _, exponent = text.lower().partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return 10.0 ** (int(exponent or 0) - decimals)


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
    for a, b in zip(e_nums, g_nums):
        if not re.search(r"[.e]", a):  # an integer (a count, an arm, a joint) is exact
            if a != b:
                return False
        elif not abs(float(a) - float(b)) <= max(RTOL * abs(float(a)), 1.000001 * _last_digit(a)):
            return False
    return True


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
    """The README's count of the default grid's schemes: the fixed-step and the error-controlled ones."""
    from coopctrl.analysis.tradeoff import parse_integrators
    from coopctrl.integrators import ERROR_CONTROLLED

    words = {3: "three", 4: "four", 5: "five", 6: "six", 7: "seven"}
    text = " ".join(README.split())
    assert f"default: all {words[len(INTEGRATORS)]} fixed-step integrators" in text
    assert f"all {words[len(ERROR_CONTROLLED)]} error-controlled integrators" in text
    assert len(parse_integrators(None)) == len(INTEGRATORS) + len(ERROR_CONTROLLED)


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


# ---------------------------------------------------------------------------------------------------
# The README's deterministic examples, rerun in-process and compared with the figures the README
# prints (issue 21 item 9). Every expected figure is parsed from README.md, never written here.
# Deterministic runs are bit-identical on one machine; another CPU or library version may move the
# last printed digit of a 4-significant-digit figure, hence RTOL above (2e-3 relative).
# Wall times, real-time factors and sweeps with timeouts are not compared: they depend on the machine.

PANDA = ".venv/bin/coopctrl run two_panda_carry"
# the former euler_singularity scene (before rotation charts, issue 20): the book's angles, forms and path
EULER_INVARIANT = (".venv/bin/coopctrl run euler_singularity -q --set 'scene.rotations=\"book\"' "
                   "--set 'trajectory.orientation=\"euler\"' --set 'trajectory.via[1].pose=[0, 0, 0.6, 0, 1.45, 0]' "
                   "--set 'springs[0].rotation_form=\"book\"' --set 'springs[1].rotation_form=\"book\"'")
EULER_BOOK = (EULER_INVARIANT + " --set 'springs[0].damping_form=\"book\"' --set 'springs[1].damping_form=\"book\"'")
STIFF_STABILITY = ".venv/bin/coopctrl stability stiff_grasp_extreme"
URDF_SNIPPET_MARK = "from plants.arms import from_urdf, panda"


def _bash_commands() -> list[tuple[str, list[str]]]:
    """Every command of the README's ``bash`` blocks (continuation lines joined), with the ``# ...``
    comment lines that follow it (what the README says it prints)."""
    out = []
    for block in re.findall(r"```bash\n(.*?)```", README, re.S):
        for line in block.replace("\\\n", " ").splitlines():
            text = " ".join(line.split())
            if text.startswith("# ") and out:
                out[-1][1].append(text[2:])
            elif text:
                out.append((text.split("  #")[0].strip() if "  #" in line else text, []))
    return out


def _cli(command: str, capsys) -> tuple[int, str, str]:
    """Run a README command in this process; ``(exit code, stdout, stderr)``."""
    import shlex

    from coopctrl import cli

    shown = " ".join(README.replace("\\\n", " ").split())  # continuation lines joined
    assert " ".join(command.split()) in shown, f"README.md no longer shows {command!r}"
    words = shlex.split(command)
    assert words[0] == ".venv/bin/coopctrl"
    capsys.readouterr()
    code = cli.main(words[1:])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_two_panda_carry_prints_what_the_readme_shows(capsys):
    code, out, err = _cli(PANDA, capsys)
    assert code == 0, err
    got = dict(_split(ln) for ln in out.splitlines() if ln.strip())
    expected = _printed_block("`coopctrl run two_panda_carry` prints")
    assert len(expected) >= 6
    for line in expected:
        key, value = _split(line)
        assert key in got, f"README shows {key!r}, the run does not print it"
        assert key not in TIMINGS
        assert _same(value, got[key]), f"{key}: README {value!r}, run {got[key]!r}"


def test_euler_singularity_examples_end_as_the_readme_says(capsys):
    stated = re.search(r"The first command stops with `diverged at t = ([\d.]+) s` \(exit (\d)\)", README)
    assert stated, "README no longer states where euler_singularity stops"
    code, _, err = _cli(EULER_BOOK, capsys)
    assert code == int(stated.group(2)), err
    got = re.search(r"diverged at t = ([\d.]+) s", err)
    assert got, err
    assert float(got.group(1)) == pytest.approx(float(stated.group(1)), rel=RTOL), err
    assert "The second runs the whole 2.5 s carry ok (exit 0)" in " ".join(README.split())
    code, _, err = _cli(EULER_INVARIANT, capsys)
    assert code == 0, err


def test_preflight_examples_print_what_the_readme_shows(capsys):
    examples = [(c, said) for c, said in _bash_commands() if c.startswith(".venv/bin/coopctrl check") and said]
    assert len(examples) >= 2
    for command, said in examples:
        code, out, err = _cli(command, capsys)
        assert code == 1 and out == "", (command, err)
        expected = said[0].split("(...)")[0].strip()  # the README elides the rest of the line
        assert expected.startswith("coopctrl: failed: pre-flight:")
        assert _same(expected, err.strip()[:len(expected)]), f"{command}:\nREADME {expected}\nrun    {err.strip()}"


def test_urdf_python_example_prints_what_the_readme_shows(capsys):
    blocks = re.findall(r"```python\n(.*?)```", README, re.S)
    code = next(b for b in blocks if URDF_SNIPPET_MARK in b)
    capsys.readouterr()
    exec(compile(code, "README.md (URDF example)", "exec"), {})
    got = [ln for ln in capsys.readouterr().out.splitlines() if ln.strip()]
    # the README's block after "prints" that follows the snippet is its output
    after = README[README.index(URDF_SNIPPET_MARK):].split("\nprints\n", 1)[1]
    expected = [ln for ln in after.split("```", 2)[1].splitlines()[1:] if ln.strip()]
    assert len(got) == len(expected) == 4
    for e, g in zip(expected, got):
        assert _same(" ".join(e.split()), " ".join(g.split())), f"README {e!r}, run {g!r}"


def test_force_loop_margins_are_those_quoted():
    from coopctrl import tuning

    quoted = re.search(
        r"For `(\w+)` \(the scene loaded above\),\s+arm (\d) (\w+): phase margin\s+([\d.]+) deg at ([\d.]+) rad/s, "
        r"gain margin ([\d.]+) at the Nyquist frequency,\s+bandwidth ([\d.]+) rad/s = ([\d.]+) x the elastic mode it "
        r"acts through \(([\d.]+) rad/s\)", README)
    assert quoted, "README no longer quotes the force loop's margins in the expected words"
    scene, arm, component = quoted.group(1), int(quoted.group(2)), quoted.group(3)
    assert f'coopctrl.load_scenario("scenarios/{scene}.toml")' in README
    loop = tuning.force_loop(tuning.linearize_closed_loop(coopctrl.load_scenario(REPO / "scenarios" / f"{scene}.toml")))
    assert (loop.follower + 1, loop.component) == (arm, component)
    got = (loop.margins.phase_margin, loop.margins.gain_crossover, loop.margins.gain_margin, loop.bandwidth,
           loop.bandwidth / loop.elastic_mode, loop.elastic_mode)
    for text, value in zip(quoted.groups()[3:], got):
        # the quoted text is the value rounded to its last digit (half a unit), plus RTOL for another machine
        assert abs(value - float(text)) <= 0.5 * _last_digit(text) + RTOL * abs(value), (text, value)


def test_stability_table_is_the_one_printed(capsys):
    code, out, err = _cli(STIFF_STABILITY, capsys)
    assert code == 0, err
    expected = _printed_block(f"`{STIFF_STABILITY.removeprefix('.venv/bin/')}` prints")
    header = expected[0]
    lines = out.splitlines()
    assert " ".join(header.split()) in [" ".join(ln.split()) for ln in lines], f"README header {header!r}"
    start = next(k for k, ln in enumerate(lines) if " ".join(ln.split()) == " ".join(header.split()))
    rows = [" ".join(ln.split()) for ln in lines[start + 1:start + len(expected)]]
    assert len(rows) == len(expected) - 1 and all(rows)
    for e, g in zip(expected[1:], rows):
        assert _same(" ".join(e.split()), g), f"README {e!r}\nrun    {g!r}"
