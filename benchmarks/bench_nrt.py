"""What numba's reference counting would cost the compiled tick: this tree beside a copy without ``_nrt=False``.

Run from the repository root: python benchmarks/bench_nrt.py [--scenes a,b] [--rounds N] [--quick]

The kernels of ``plants`` and ``coopctrl`` are compiled with numba's private option ``_nrt=False`` (issue 18
asks for public numba only). This benchmark measures what dropping it costs: it copies ``plants`` and
``coopctrl`` to a temporary folder with every ``_nrt=False`` removed (numba's default: its runtime on, an
atomic reference count per array passed or viewed), compiles both trees once, each on its own fresh
numba cache (``NUMBA_CACHE_DIR``; about three minutes each, not timed), then alternates ``rounds`` times
a child process per tree that times ``closed_loop(scenario).run(x0, duration)`` three times and keeps its
best per-tick wall time [us]. It prints, per scene, the median over the rounds of each tree and their
ratio (copy / this tree). The allocation-free kernels need no runtime; the ratio is the price of
leaving the private option.
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_SCENES = ("spatial_two_puma_carry", "planar_two_arm_lift")

CHILD = r"""
import sys, time
import coopctrl
from coopctrl.scenario import build
from coopctrl.simulator import closed_loop
for name in sys.argv[1].split(","):
    scenario = coopctrl.load_scenario(sys.argv[2] + "/scenarios/" + name + ".toml")
    loop = closed_loop(scenario)
    x0 = build.initial_state(scenario, loop)
    duration = scenario.simulation.duration
    loop.run(x0, duration)  # compiled or loaded, not timed
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        rec = loop.run(x0, duration)
        best = min(best, time.perf_counter() - t0)
    print(name, best / len(rec["t"]) * 1e6, coopctrl.__file__, flush=True)
"""


def _copy_without_nrt(dst: Path) -> int:
    """``plants`` and ``coopctrl`` copied to ``dst`` with ``_nrt=False`` removed; returns the edits made."""
    edits = 0
    for package in ("plants", "coopctrl"):
        shutil.copytree(REPO / package, dst / package, ignore=shutil.ignore_patterns("__pycache__"))
        for path in (dst / package).rglob("*.py"):
            text = path.read_text(encoding="utf-8")
            new, n = re.subn(r",\s*_nrt=(False|runtime)\)", ")", text)
            new, k = re.subn(r"\(_nrt=False\)", "()", new)
            if n + k:
                path.write_text(new, encoding="utf-8")
                edits += n + k
    return edits


def _per_tick(tree: Path, cache: Path, scenes: str) -> dict[str, float]:
    env = dict(os.environ, PYTHONPATH=str(tree), NUMBA_CACHE_DIR=str(cache))
    # run in the tree's folder: ``python -c`` puts the working directory first on the import path
    out = subprocess.run([sys.executable, "-c", CHILD, scenes, str(REPO)], env=env, capture_output=True, text=True,
                         check=True, cwd=tree).stdout
    rows = [line.split() for line in out.splitlines() if line.strip()]
    if any(not Path(row[2]).resolve().is_relative_to(tree.resolve()) for row in rows):
        raise RuntimeError(f"the child imported coopctrl from outside {tree}: {rows}")
    return {row[0]: float(row[1]) for row in rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", default=",".join(DEFAULT_SCENES), help="comma-separated scene names")
    ap.add_argument("--rounds", type=int, default=3, help="alternated rounds after the compile (default 3)")
    ap.add_argument("--quick", action="store_true", help="1 round of the planar scene (a smoke run; both trees are still compiled)")
    args = ap.parse_args(argv)
    if args.quick:
        args.rounds, args.scenes = 1, "planar_two_arm_lift"
    print("command: python benchmarks/bench_nrt.py " + " ".join(argv if argv is not None else sys.argv[1:]))
    with tempfile.TemporaryDirectory(prefix="coopctrl-nrt-") as tmp:
        tmp = Path(tmp)
        edits = _copy_without_nrt(tmp / "tree")
        print(f"copy without _nrt=False: {edits} decorators edited")
        trees = {"this tree (_nrt=False)": REPO, "numba's default (runtime on)": tmp / "tree"}
        caches = {label: tmp / f"cache{i}" for i, label in enumerate(trees)}
        for label, tree in trees.items():  # compile each tree on its own cache (not timed)
            _per_tick(tree, caches[label], args.scenes)
        times: dict[str, dict[str, list[float]]] = {label: {} for label in trees}
        for _ in range(args.rounds):
            for label, tree in trees.items():
                for scene, us in _per_tick(tree, caches[label], args.scenes).items():
                    times[label].setdefault(scene, []).append(us)
    base, other = list(trees)
    print(f"{'scene':28s} {base:>26s} {other:>30s}  ratio   (us per tick, medians of {args.rounds} rounds)")
    for scene in args.scenes.split(","):
        a, b = statistics.median(times[base][scene]), statistics.median(times[other][scene])
        print(f"{scene:28s} {a:26.1f} {b:30.1f}  {b / a:5.2f}x")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
