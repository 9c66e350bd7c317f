"""Benchmark: start-up of ``coopctrl run``, on an empty numba cache (cold) and on a filled one (warm).

Run from the repository root::

    python benchmarks/bench_startup.py [--scene spatial_two_puma_carry] [--cold 3] [--warm 5] [--top 15]
        [--second planar_two_arm_lift --second spatial_two_puma_carry:simulation.integrator=implicit_euler] [--quick]

Each run is a new process ``python -m coopctrl run scenarios/<scene>.toml --quiet`` with
``NUMBA_CACHE_DIR`` set to a fresh temporary directory (so neither the worktree's ``__pycache__``
nor another run's cache is used), measured from the moment the process is started:

* ``cold``: the first run on the empty cache (numba compiles every kernel the scene needs and
  writes it to the cache), total wall time [s];
* ``second kind``: after each cold run, on the cache it filled, the first run of another scene kind
  (``--second SCENE[:PATH=VALUE,...]``, repeatable; default a planar scene and the carry with an implicit
  integrator), each on a copy of that cache: the extra time [s] a user waits when switching kind;
* ``warm``: later runs on the cache the cold run filled: the time until the compiled loop starts
  its first tick, and the total wall time [s].

Beside each wall time, the process's CPU time (user + system) [s]: on a shared machine the wall
time grows with the load, the CPU time much less (it is what a quiet machine's wall time would be,
as the start-up runs on one core).

The first tick is taken in the child process by wrapping ``coopctrl.loop.kernel.run_ticks`` (the
compiled loop, called from Python in chunks of ticks): the moment of its first call that runs a
tick. The child also records numba's ``numba:compile`` events (:mod:`numba.core.event`) and the
cold run prints the top ``--top`` compiled functions by their own compile time (exclusive of the
functions compiled inside them). A load from numba's cache is not a compile event: on a warm run the
events left are what is compiled anew in every process (functions without ``cache=True``).

Targets (issue 18): the first run on an empty cache takes at most 30 s; the first run of a second
kind (planar, or an implicit integrator) at most 15 s more; a warm ``coopctrl run`` reaches its first
tick within 1 s. The machine is shared: the load average is printed, and the
figures are medians over the repeats (docs/performance.md: runs agree only to ~1.5x).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
#: The scene the targets are stated for.
CARRY = "spatial_two_puma_carry"
#: Targets of issue 18 [s].
COLD_TARGET_S = 30.0
SECOND_KIND_TARGET_S = 15.0
WARM_FIRST_TICK_TARGET_S = 1.0
#: The default second kinds: ``SCENE`` or ``SCENE:PATH=VALUE,...`` (overrides given to ``--set``).
SECOND_KINDS = ("planar_two_arm_lift", f"{CARRY}:simulation.integrator=implicit_euler")

#: The child: times the first tick and the compile events of one ``coopctrl run``, then runs the CLI.
#: argv: report path, then the CLI's arguments. Writes a JSON report at exit.
_CHILD = r"""
import json, sys, time
report_path = sys.argv[1]
sys.argv = ["coopctrl"] + sys.argv[2:]
report = {"first_tick_epoch": None, "compiles": []}
from numba.core import event as ev

class _Recorder(ev.Listener):
    # inclusive and exclusive time of each numba:compile event (nested compiles are subtracted)
    def __init__(self):
        self.stack = []
    def on_start(self, event):
        self.stack.append([time.perf_counter(), 0.0])
    def on_end(self, event):
        t0, inner = self.stack.pop()
        dt = time.perf_counter() - t0
        if self.stack:
            self.stack[-1][1] += dt
        data = event.data or {}
        disp = data.get("dispatcher")
        name = getattr(getattr(disp, "py_func", None), "__module__", "?") + "." + getattr(disp, "__qualname__", getattr(getattr(disp, "py_func", None), "__qualname__", "?"))
        report["compiles"].append([name, str(data.get("args", "")), dt, dt - inner])

ev.register("numba:compile", _Recorder())

def _hook():
    try:
        from coopctrl.loop import kernel as K
    except Exception:
        return
    inner = K.run_ticks
    def run_ticks(*args, **kwargs):
        # run_ticks(model, data, k0, k_stop): the first call that runs a tick is the first tick
        if report["first_tick_epoch"] is None and len(args) > 3 and args[3] > args[2]:
            report["first_tick_epoch"] = time.time()
        return inner(*args, **kwargs)
    K.run_ticks = run_ticks

_hook()
import runpy
try:
    runpy.run_module("coopctrl", run_name="__main__", alter_sys=True)
except SystemExit as exc:
    report["exit"] = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
else:
    report["exit"] = 0
finally:
    with open(report_path, "w") as f:
        json.dump(report, f)
"""


def run_once(scene_path: str, cache_dir: str, work: str, sets: tuple[str, ...] = ()) -> dict:
    """One ``coopctrl run`` (with ``--set`` of each of ``sets``) in a new process on ``cache_dir``; its wall
    time, first tick and compiles."""
    report_path = os.path.join(work, "report.json")
    if os.path.exists(report_path):
        os.remove(report_path)
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""))
    cmd = [sys.executable, "-c", _CHILD, report_path, "run", scene_path, "--quiet", *(a for v in sets for a in ("--set", v))]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.time()
    proc = subprocess.run(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    total = time.time() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if not os.path.exists(report_path):
        raise SystemExit(f"bench_startup: the child wrote no report (exit {proc.returncode}): {proc.stderr[-2000:]}")
    with open(report_path) as f:
        report = json.load(f)
    if proc.returncode not in (0, 1):
        raise SystemExit(f"bench_startup: coopctrl run exited {proc.returncode}: {proc.stderr[-2000:]}")
    first = report["first_tick_epoch"]
    return {"total": total, "cpu": cpu, "first_tick": None if first is None else first - t0,
            "compiles": report["compiles"], "exit": proc.returncode}


def compile_table(compiles, top):
    """Lines of the top ``top`` functions by exclusive compile time [s] (summed over their signatures)."""
    per = {}
    for name, args, incl, excl in compiles:
        e = per.setdefault(name, [0.0, 0, 0.0])
        e[0] += excl
        e[1] += 1
        e[2] = max(e[2], incl)
    rows = sorted(per.items(), key=lambda kv: -kv[1][0])
    lines = [f"  {'function':70s} {'own s':>7s} {'sigs':>5s} {'incl s':>7s}"]
    for name, (excl, count, incl) in rows[:top]:
        lines.append(f"  {name[-70:]:70s} {excl:7.2f} {count:5d} {incl:7.2f}")
    lines.append(f"  ({len(compiles)} compile events, {len(per)} functions, {sum(c[3] for c in compiles):.1f} s in all)")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default=CARRY, help=f"scene name in scenarios/ (default {CARRY})")
    ap.add_argument("--cold", type=int, default=3, help="cold runs, each on a new empty cache (default 3)")
    ap.add_argument("--warm", type=int, default=5, help="warm runs on the cache of the first cold run (default 5)")
    ap.add_argument("--top", type=int, default=15, help="functions listed in the compile profile (default 15)")
    ap.add_argument("--second", action="append", metavar="SCENE[:PATH=VALUE,...]",
                    help="a second scene kind run after each cold run on a copy of its cache (repeatable; default "
                    f"{' and '.join(SECOND_KINDS)}; 'none': no second kind)")
    ap.add_argument("--quick", action="store_true", help="1 cold run and 2 warm runs")
    args = ap.parse_args(argv)
    if args.quick:
        args.cold = min(args.cold, 1)
        args.warm = min(args.warm, 2)
    scene_path = os.path.join(ROOT, "scenarios", f"{args.scene}.toml")
    if not os.path.isfile(scene_path):
        print(f"bench_startup: --scene {args.scene!r}: no file scenarios/{args.scene}.toml", file=sys.stderr)
        return 2
    if args.cold < 1 or args.warm < 1:
        print("bench_startup: --cold and --warm must be at least 1", file=sys.stderr)
        return 2
    seconds = []  # (label, scene path, sets)
    for spec in (args.second or list(SECOND_KINDS)):
        if spec == "none":
            continue
        name, _, sets = spec.partition(":")
        path = os.path.join(ROOT, "scenarios", f"{name}.toml")
        if not os.path.isfile(path):
            print(f"bench_startup: --second {spec!r}: no file scenarios/{name}.toml", file=sys.stderr)
            return 2
        seconds.append((spec, path, tuple(v for v in sets.split(",") if v)))
    print(f"command: {' '.join(['python', *sys.argv])}")
    print(f"machine: {platform.machine()} python {platform.python_version()}, {os.cpu_count()} cpus, "
          f"load average {os.getloadavg()[0]:.2f}")
    work = tempfile.mkdtemp(prefix="coopctrl_startup_")
    try:
        colds, cold_cpu, warms_first, warms_total, warm_cpu = [], [], [], [], []
        extra = {label: [] for label, _, _ in seconds}  # the second kinds' first runs [s]
        second_profiles = {}
        first_cache = None
        profile = None
        for i in range(args.cold):
            cache = os.path.join(work, f"cache{i}")
            os.makedirs(cache)
            r = run_once(scene_path, cache, work)
            colds.append(r["total"])
            cold_cpu.append(r["cpu"])
            print(f"  cold run {i + 1}: {r['total']:.1f} s, cpu {r['cpu']:.1f} s (first tick at {r['first_tick'] or float('nan'):.1f} s, "
                  f"exit {r['exit']}, load {os.getloadavg()[0]:.2f})", flush=True)
            if first_cache is None:
                first_cache, profile = cache, r["compiles"]
            for j, (label, path, sets) in enumerate(seconds):
                copy = os.path.join(work, f"cache{i}_second{j}")
                shutil.copytree(cache, copy)
                s = run_once(path, copy, work, sets)
                extra[label].append(s["total"])
                second_profiles.setdefault(label, s["compiles"])
                print(f"    then the first run of {label}: {s['total']:.1f} s more, cpu {s['cpu']:.1f} s "
                      f"(exit {s['exit']}, load {os.getloadavg()[0]:.2f})", flush=True)
                if i:
                    shutil.rmtree(copy, ignore_errors=True)
        for i in range(args.warm):
            r = run_once(scene_path, first_cache, work)
            warms_total.append(r["total"])
            warm_cpu.append(r["cpu"])
            if r["first_tick"] is not None:
                warms_first.append(r["first_tick"])
            print(f"  warm run {i + 1}: first tick at {r['first_tick'] or float('nan'):.2f} s, total {r['total']:.2f} s, "
                  f"cpu {r['cpu']:.2f} s "
                  f"({sum(c[3] for c in r['compiles']):.2f} s in numba compile/cache-load events, load "
                  f"{os.getloadavg()[0]:.2f})", flush=True)
            if r["compiles"]:
                names = sorted({c[0] for c in r["compiles"]})
                print(f"    compiled anew although the cache was warm: {', '.join(names[:8])}"
                      f"{' ...' if len(names) > 8 else ''}")
    finally:
        shutil.rmtree(work, ignore_errors=True)
    cold = float(np.median(colds))
    first = float(np.median(warms_first)) if warms_first else float("nan")
    total = float(np.median(warms_total))
    print(f"\ncompile profile of the first cold run (top {args.top} by own compile time):")
    for line in compile_table(profile, args.top):
        print(line)
    for label, _, _ in seconds:
        print(f"\ncompile profile of the first run of {label} after the cold run (top {args.top}):")
        for line in compile_table(second_profiles[label], args.top):
            print(line)
    print(f"\n{args.scene}: cold first run {cold:.1f} s (median of {len(colds)}; target <= {COLD_TARGET_S:.0f} s: "
          f"{'PASS' if cold <= COLD_TARGET_S else 'MISS'}), cpu {float(np.median(cold_cpu)):.1f} s")
    print(f"{args.scene}: warm run reaches its first tick at {first:.2f} s (median of {len(warms_first)}; target <= "
          f"{WARM_FIRST_TICK_TARGET_S:.0f} s: {'PASS' if first <= WARM_FIRST_TICK_TARGET_S else 'MISS'}), "
          f"total {total:.2f} s, cpu {float(np.median(warm_cpu)):.2f} s")
    for label, _, _ in seconds:
        more = float(np.median(extra[label]))
        print(f"first run of a second kind, {label}: {more:.1f} s more (median of {len(extra[label])}; target <= "
              f"{SECOND_KIND_TARGET_S:.0f} s: {'PASS' if more <= SECOND_KIND_TARGET_S else 'MISS'})")
    print(f"load average at the end: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
