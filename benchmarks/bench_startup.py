"""Benchmark: start-up of ``coopctrl run`` on empty caches, the way a new user's first run meets it.

Run from the repository root::

    python benchmarks/bench_startup.py [--scenes spatial_two_puma_carry ...] [--repeats 3] [--quick]

Each run is a new process ``python -m coopctrl run scenarios/<scene>.toml --quiet`` with ``XDG_CACHE_HOME`` and
``NUMBA_CACHE_DIR`` set to fresh temporary directories (no cache of an earlier run is used), measured from the
moment the process is started:

* ``whole``: the command's wall time [s] and its CPU time (user + system) [s]: on a shared machine the wall time
  grows with the load, the CPU time much less;
* ``first tick``: the time until the compiled tick (``coopctrl._core.Tick.run_ticks``) is first called [s];
* ``compiled``: the numba functions compiled in the process (``numba:compile`` events; 0 when nothing of the run
  compiles at run time), and whether numba was imported at all.

Targets (issue 42): the first ``coopctrl run spatial_two_puma_carry`` after a fresh install takes at most 3 s as a
whole, and every shipped scene's first run at most 3 s; the first tick starts within 1 s of the command. Medians
over the repeats; the load average is printed.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
#: The scene the whole-command target is stated for.
CARRY = "spatial_two_puma_carry"
#: Targets of issue 42 [s].
WHOLE_TARGET_S = 3.0
FIRST_TICK_TARGET_S = 1.0

#: The child: records when the compiled tick first runs and numba's compile events, then runs the CLI.
#: argv: report path, then the CLI's arguments. Writes a JSON report at exit.
_CHILD = r"""
import atexit, json, sys, time
report_path = sys.argv[1]
sys.argv = ["coopctrl"] + sys.argv[2:]
report = {"first_tick_epoch": None, "compiles": 0, "numba_imported": False}

def _write():
    report["numba_imported"] = "numba" in sys.modules
    with open(report_path, "w") as f:
        json.dump(report, f)
atexit.register(_write)

class _Finder:  # count numba's compile events if numba is ever imported
    def find_spec(self, name, path=None, target=None):
        if name == "numba.core.event" and not getattr(self, "done", False):
            self.done = True
            import importlib
            sys.meta_path.remove(self)
            ev = importlib.import_module("numba.core.event")
            class _Count(ev.Listener):
                def on_start(self, event):
                    report["compiles"] += 1
                def on_end(self, event):
                    pass
            ev.install_listener("numba:compile", _Count())
            return importlib.util.find_spec(name)
        return None
sys.meta_path.insert(0, _Finder())

import coopctrl._core as core
_Tick = core.Tick

class _Timed:
    def __init__(self, *args):
        self._tick = _Tick(*args)
    def run_ticks(self, *args):
        if report["first_tick_epoch"] is None:
            report["first_tick_epoch"] = time.time()
        return self._tick.run_ticks(*args)
    def __getattr__(self, name):
        attr = getattr(self._tick, name)
        if name in ("reference_step",) and report["first_tick_epoch"] is None:
            report["first_tick_epoch"] = time.time()
        return attr
core.Tick = _Timed
from coopctrl.cli import main
raise SystemExit(main())
"""


def _scenes(args) -> list[str]:
    if args.scenes:
        return args.scenes
    if args.quick:
        return [CARRY, "planar_two_arm_lift"]
    return sorted(p.stem for p in (ROOT / "scenarios").glob("*.toml"))


def one_run(scene: str) -> dict:
    """One first run of ``scene`` in a new process on empty caches: wall, CPU and first-tick times [s]."""
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, XDG_CACHE_HOME=os.path.join(tmp, "cache"), NUMBA_CACHE_DIR=os.path.join(tmp, "numba"),
                   MPLBACKEND="Agg")
        report_path = os.path.join(tmp, "report.json")
        cmd = [sys.executable, "-c", _CHILD, report_path, "run", str(ROOT / "scenarios" / f"{scene}.toml"), "--quiet"]
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.time()
        done = subprocess.run(cmd, env=env, cwd=tmp, capture_output=True, text=True)
        wall = time.time() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        try:
            with open(report_path) as f:
                report = json.load(f)
        except OSError:
            report = {"first_tick_epoch": None, "compiles": -1, "numba_imported": None}
    first = report["first_tick_epoch"] - t0 if report["first_tick_epoch"] is not None else float("nan")
    return {"wall": wall, "cpu": cpu, "first_tick": first, "compiles": report["compiles"],
            "numba": report["numba_imported"], "exit": done.returncode}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--scenes", nargs="*", help="scenes to run (default: every shipped scene)")
    parser.add_argument("--repeats", type=int, default=3, help="first runs per scene (median)")
    parser.add_argument("--quick", action="store_true", help="the carry and the planar lift, 2 repeats each")
    args = parser.parse_args(argv)
    repeats = 2 if args.quick and args.repeats == 3 else args.repeats
    print(f"python {platform.python_version()}, {os.cpu_count()} cores, load average "
          f"{', '.join(f'{v:.2f}' for v in os.getloadavg())}; {repeats} first runs per scene on empty caches")
    print(f"{'scene':<30} {'whole [s]':>9} {'cpu [s]':>8} {'first tick [s]':>15} {'numba compiles':>15} "
          f"{'numba imported':>15} {'exit':>5}")
    worst = 0.0
    carry = None
    for scene in _scenes(args):
        runs = [one_run(scene) for _ in range(repeats)]
        med = {key: float(np.median([r[key] for r in runs])) for key in ("wall", "cpu", "first_tick")}
        compiles = max(r["compiles"] for r in runs)
        imported = any(r["numba"] for r in runs)
        exits = sorted({r["exit"] for r in runs})
        print(f"{scene:<30} {med['wall']:9.2f} {med['cpu']:8.2f} {med['first_tick']:15.2f} {compiles:15d} "
              f"{str(imported):>15} {','.join(map(str, exits)):>5}")
        worst = max(worst, med["wall"])
        if scene == CARRY:
            carry = med
    if carry is not None:
        print(f"{CARRY}: whole command {carry['wall']:.2f} s (target <= {WHOLE_TARGET_S:g} s), first tick "
              f"{carry['first_tick']:.2f} s (target <= {FIRST_TICK_TARGET_S:g} s)")
    print(f"slowest scene's first run: {worst:.2f} s (target <= {WHOLE_TARGET_S:g} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
