"""A seeded fuzz of the command line (issue 11): mutated scenes, mangled arguments, and signals at random
moments to ``run`` and to ``sweep`` with worker processes.

Every case asserts what the user is promised:

- no traceback, and no "internal error" (an unforeseen exception) on stderr;
- one of the documented exit codes (0, 1, 2; 130 on SIGINT, 143 on SIGTERM), with a ``coopctrl:`` line
  on stderr whenever it is not 0;
- no hang: each case is bounded (an alarm in this process, a timeout on a child process);
- no temporary file left in the output directory, and no process left behind;
- no ``ok`` over non-finite results or over a load split that does not balance the load: every split the
  load distribution returned as solved is re-checked here, independently, against ``G F = w_N``.

The draws are seeded (``SEED``), so a failure is reproducible; the budget is about a minute.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil
import pytest

from _processes import descendants, still_alive

from coopctrl import cli
from coopctrl.load_distribution import LoadDistribution

REPO = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "PYTHONPATH": str(REPO) + os.pathsep + os.environ.get("PYTHONPATH", "")}
SEED = 20261201
#: Bound on one in-process case [s]; the longest legitimate case simulates 0.05 s of a scene.
CASE_BOUND_S = 60
CHILD_BOUND_S = 240

SCENES = ("planar_two_arm_lift", "spatial_two_puma_carry", "heavy_payload_torque_limits", "contact_points_only")

#: Mutations (path, values): physical extremes, wrong types, values at the edge of floating point.
MUTATIONS = (
    ("springs[0].stiffness", ["1e-300", "1e308", "1.7976931348623157e308", "-1", "nan", "inf", "'soft'", "1e9"]),
    ("springs[0].damping", ["0", "1e300", "-5", "1e6"]),
    ("springs[0].torsion_damping", ["0", "1e12", "nan"]),
    ("springs[0].damping_form", ['"book"', '"frame_invariant"', '"other"', "1"]),
    ("object.mass", ["1e-300", "1e300", "0", "-2", "1e-3", "1e3"]),
    ("simulation.duration", ["1e300", "0", "-1", "1e-9", "nan"]),
    ("simulation.control_period", ["1e-300", "1e3", "0", "0.01"]),
    ("simulation.integrator", ['"euler"', '"implicit_euler"', '"bogus"', "3"]),
    ("sensors.forces.noise_std", ["1e300", "-1", "1e3", "nan"]),
    ("load_distribution.eps_abs", ["100", "0", "1e-300"]),
    ("load_distribution.max_iter", ["1", "0", "-3", "2.5"]),
    ("controllers.leader.natural_frequency", ["1e300", "0", "1e-300", "-1"]),
    ("scene.gravity", ["0", "1e300", "-9.81", "nan"]),
    ("no.such.key", ["1"]),
)

#: Mangled command lines: wrong options, values and names (each must be a one-line exit 2).
BAD_ARGUMENTS = (
    ["run", "no_such_scene"],
    ["run", "planar_two_arm_lift", "--set", "simulation.duration"],
    ["run", "planar_two_arm_lift", "--bogus"],
    ["sweep", "planar_two_arm_lift", "--grid", "simulation.seed="],
    ["sweep", "planar_two_arm_lift", "--grid", "simulation.seed=0", "--jobs", "0"],
    ["sweep", "planar_two_arm_lift", "--grid", "simulation.seed=0", "--run-timeout", "-2"],
    ["tradeoff", "planar_two_arm_lift", "--steps", "T/0"],
    ["tradeoff", "planar_two_arm_lift", "--integrators", "warp_drive"],
    ["tradeoff", "planar_two_arm_lift", "--reference-rtol", "-1"],
    ["fidelity", "planar_two_arm_lift"],
    ["fidelity", "--repeats", "0"],
    ["check", "no_such_scene"],
    ["stability", "planar_two_arm_lift", "--integrators", "rk5"],
    ["nonsense"],
)


class Hang(BaseException):
    """A case went past its bound (a BaseException: the command line's handlers do not catch it)."""


@pytest.fixture
def bounded():
    """Run a case with an alarm: a hang fails the test instead of stopping the suite."""
    def expire(signum, frame):
        raise Hang(f"case still running after {CASE_BOUND_S} s")

    previous = signal.signal(signal.SIGALRM, expire)
    yield lambda: signal.setitimer(signal.ITIMER_REAL, CASE_BOUND_S)
    signal.setitimer(signal.ITIMER_REAL, 0.0)
    signal.signal(signal.SIGALRM, previous)


@pytest.fixture
def checked_splits(monkeypatch):
    """Every split the load distribution returns as solved, re-checked against the balance ``G F = w_N``
    here (independently of its own check); returns the list of relative residuals per case."""
    residuals: list[float] = []
    solve = LoadDistribution.solve

    def checking(self, *args, **kw):
        split = solve(self, *args, **kw)
        if not split.held:
            pb = self.problem
            F = np.asarray(split.F, dtype=float).reshape(-1)
            load = max(1.0, float(np.max(np.abs(pb.w))))
            residuals.append(float(np.max(np.abs(pb.G @ F - pb.w))) / load)
        return split

    monkeypatch.setattr(LoadDistribution, "solve", checking)
    return residuals


def check_outcome(code: int, out: str, err: str, json_out: bool) -> dict | None:
    assert "Traceback" not in err, err
    assert "internal error" not in err, err
    assert code in (0, 1, 2), (code, err)
    if code != 0:
        lines = [line for line in err.splitlines() if line.startswith("coopctrl: ")]
        assert lines, err
    if json_out and code in (0, 1) and out.strip():
        return json.loads(out)  # strict JSON: stdout holds nothing else
    return None


def no_debris(directory: Path) -> None:
    if directory.exists():
        left = [p.name for p in directory.rglob("*") if p.name.startswith(".") or p.name.endswith(".tmp")]
        assert left == [], left


def test_fuzz_scenario_mutations_and_arguments(tmp_path, capsys, bounded, checked_splits):
    rng = np.random.default_rng(SEED)
    cases = 0
    outcomes: list[tuple[int, str | None, int]] = []
    for k in range(28):
        scene = SCENES[rng.integers(len(SCENES))]
        sets = {"simulation.duration": "0.05"}
        for _ in range(rng.integers(1, 3)):
            path, values = MUTATIONS[rng.integers(len(MUTATIONS))]
            sets[path] = values[rng.integers(len(values))]
        command = "check" if rng.random() < 0.3 else "run"
        args = [command, scene, *(a for p, v in sets.items() for a in ("--set", f"{p}={v}"))]
        out_dir = tmp_path / f"case{k}"
        if command == "run":
            args += ["--json"] + (["--out", str(out_dir)] if rng.random() < 0.5 else [])
        checked_splits.clear()
        bounded()
        code = cli.main(args)
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        out, err = capsys.readouterr()
        summary = check_outcome(code, out, err, command == "run")
        no_debris(out_dir)
        outcomes.append((code, summary["status"] if summary else None, len(checked_splits)))
        if summary is not None:
            assert (summary["status"] == "ok") == (code == 0), (args, summary["status"], code)
            if summary["status"] == "ok":  # no ok over non-finite metrics or an unbalanced split
                for key in ("object_position_error_rms_m", "object_position_error_max_m", "max_torque_ratio"):
                    value = summary[key]
                    assert value is not None and math.isfinite(value), (args, key, value)
                # the QP answers were checked against 1e-4 of the load (ANSWER_TOLERANCE_OF_LOAD); 1e-3
                # here is independent of that constant and still catches a split of 0 N (residual 1)
                assert all(r <= 1e-3 for r in checked_splits), (args, max(checked_splits))
        cases += 1
    for args in BAD_ARGUMENTS:
        bounded()
        code = cli.main(args)
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        out, err = capsys.readouterr()
        check_outcome(code, out, err, False)
        assert code == 2, (args, err)
        assert len(err.strip().splitlines()) == 1, err
        cases += 1
    assert cases == 28 + len(BAD_ARGUMENTS)
    # the draws reach every outcome: ok runs with checked splits, failed runs, refused input
    codes = {code for code, _, _ in outcomes}
    assert codes == {0, 1, 2}, outcomes
    assert any(code == 0 and splits > 0 for code, _, splits in outcomes), outcomes


def _in_main(pid: int, patience_s: float = CHILD_BOUND_S) -> bool:
    """Wait until the process ``pid`` runs :func:`coopctrl.cli.main` (it then catches SIGTERM: bit 15 of
    ``SigCgt`` in ``/proc/PID/status``). Before that the interpreter is starting up: a signal there meets
    Python's own behaviour, outside the project's reach (and nothing is written yet)."""
    deadline = time.monotonic() + patience_s
    while time.monotonic() < deadline:
        try:
            status = Path(f"/proc/{pid}/status").read_text()
        except OSError:
            return False
        caught = int(next(line.split()[1] for line in status.splitlines() if line.startswith("SigCgt:")), 16)
        if caught & (1 << (signal.SIGTERM - 1)):
            return True
        time.sleep(0.01)
    return False




@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="signals and process trees as on Linux")
def test_fuzz_signals_at_random_moments(tmp_path):
    """``run --out`` and ``sweep --jobs 2 --out``, each signalled (SIGINT, SIGTERM or SIGKILL) after a
    random delay: start-up, simulation, or mid-write. Ends with the signal's code (or 0 if it finished
    first), no traceback, no temporary file and no process left."""
    rng = np.random.default_rng(SEED + 1)
    expected = {signal.SIGINT: 130, signal.SIGTERM: 143, signal.SIGKILL: -signal.SIGKILL}
    stopped = []
    for k in range(5):
        out = tmp_path / f"signal{k}"
        if k % 2 == 0:
            command = ["run", "planar_two_arm_lift", "--set", f"simulation.duration={rng.uniform(2.0, 20.0):.3f}", "-q"]
            sig = (signal.SIGINT, signal.SIGTERM)[rng.integers(2)]
        else:
            command = ["sweep", "planar_two_arm_lift", "--grid", "simulation.seed=0,1,2,3", "--set",
                       f"simulation.duration={rng.uniform(1.0, 5.0):.3f}", "--jobs", "2", "-q"]
            sig = (signal.SIGINT, signal.SIGTERM, signal.SIGKILL)[rng.integers(3)]
        delay = float(rng.uniform(0.0, 4.0))  # after main() started: its imports, the simulation, the writes
        proc = subprocess.Popen([sys.executable, "-m", "coopctrl", *command, "--out", str(out)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=ENV)
        family: list[psutil.Process] = []
        try:
            assert _in_main(proc.pid) or proc.poll() is not None
            deadline = time.monotonic() + delay
            while time.monotonic() < deadline and proc.poll() is None:
                family += [p for p in descendants(proc.pid) if p.pid not in {q.pid for q in family}]
                time.sleep(0.05)
            family += [p for p in descendants(proc.pid) if p.pid not in {q.pid for q in family}]
            if proc.poll() is None:
                proc.send_signal(sig)
            _, err = proc.communicate(timeout=CHILD_BOUND_S)
        finally:
            if proc.poll() is None:
                proc.kill()
        assert proc.returncode in (0, expected[sig]), (command, sig, delay, proc.returncode, err)
        assert "Traceback" not in err, err
        no_debris(out)
        assert still_alive(family) == [], (command, sig, delay)
        stopped.append((command[0], sig.name, round(delay, 2), proc.returncode))
    # Where each signal landed depends on the machine's speed, so it is not asserted; on this machine
    # class (2 cores) the durations above put them in start-up, the simulation and the writes.
    assert len(stopped) == 5
    print("signal cases (command, signal, delay [s], exit code):", stopped)
