"""The shipped scenes on both plants, full length: the figures of docs/data/mujoco_plants.md.

Run from the repository root (needs ``pip install 'coopctrl[mujoco]'``)::

    python benchmarks/mujoco_plants.py [--out docs/data/mujoco_plants.md] [--scenes NAME ...]

For each scene it runs ``coopctrl compare-plants`` (:func:`coopctrl.mujoco.comparison.compare_plants`: the
elastic plant and MuJoCo with the same controller, every tick recorded) and writes one Markdown table of
the two runs' figures (status, object position error RMS, follower force error RMS, QP failures) with the
issue's bound on MuJoCo's position error RMS (2x the elastic plant's or 1 mm, whichever is larger) and one
table of the largest differences between the runs, with their times.
"""

from __future__ import annotations

import argparse
import platform
import sys
from datetime import datetime, timezone
from pathlib import Path

SCENES = ("two_panda_carry", "ur5e_panda_carry", "three_iiwa_tray", "spatial_two_puma_carry", "planar_two_arm_lift")
FLOOR_M = 1e-3  # [m]


#: The README's copy of the first table (the figures issue 43 asks the README to show), between these markers.
README_BEGIN, README_END = "<!-- mujoco_plants:begin (benchmarks/mujoco_plants.py) -->", "<!-- mujoco_plants:end -->"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="docs/data/mujoco_plants.md", help="the Markdown file to write")
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=SCENES, metavar="NAME")
    parser.add_argument("--quick", action="store_true",
                        help="the planar lift for 0.2 s, printed only (a smoke run: the pages keep their figures)")
    args = parser.parse_args(argv)
    import mujoco

    from coopctrl.io.atomic import atomic_write
    from coopctrl.mujoco.comparison import compare_plants
    from coopctrl.scenario import load_scenario

    runs, diffs = [], []
    ok = True
    for name in (["planar_two_arm_lift"] if args.quick else args.scenes):
        c = compare_plants(load_scenario(name, {"simulation.duration": 0.2} if args.quick else None))
        e, m = c.elastic, c.mujoco
        bound = max(2.0 * e["object_position_error_rms_m"], FLOOR_M)
        passed = m["status"] == "ok" and m["qp_failures"] == 0 and m["object_position_error_rms_m"] <= bound
        ok &= passed
        runs.append(f"| {name} | {e['duration_s']:g} | {e['status']} | {m['status']} | "
                    f"{e['object_position_error_rms_m'] * 1e3:.4g} | {m['object_position_error_rms_m'] * 1e3:.4g} | "
                    f"{bound * 1e3:.3g} | {e['follower_force_error_rms_N']:.4g} | {m['follower_force_error_rms_N']:.4g} | "
                    f"{e['qp_failures']} / {m['qp_failures']} | {'yes' if passed else 'NO'} |")
        for d in c.differences:
            diffs.append(f"| {name} | {d.signal} [{d.unit}] | {d.max_abs:.4g} | {d.time_s:.4g} | {d.rms:.4g} | {d.scale:.4g} |")
        print("\n".join(c.lines()), flush=True)
    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%d")
    text = "\n".join([
        "# The shipped scenes on the elastic plant and on MuJoCo",
        "",
        f"Written by `python benchmarks/mujoco_plants.py` on {stamp} (MuJoCo {mujoco.__version__}, Python "
        f"{platform.python_version()}, {platform.machine()}): full-length runs, the same controller on both plants "
        "(docs/mujoco.md).",
        "",
        "| scene | duration [s] | elastic | mujoco | position error RMS elastic [mm] | mujoco [mm] | bound [mm] | "
        "follower force error RMS elastic [N] | mujoco [N] | QP failures elastic / mujoco | within bound |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
        *runs,
        "",
        "Bound: the object's position error RMS on MuJoCo at most 2x the elastic plant's or 1 mm, whichever is larger.",
        "",
        "Largest differences between the two runs (mujoco minus elastic; per tick the largest norm over contacts; "
        "`signal max`: the largest norm of the signal on the elastic plant):",
        "",
        "| scene | signal | max | at t [s] | RMS | signal max |",
        "|---|---|---|---|---|---|",
        *diffs,
        "",
    ])
    if args.quick:
        return 0 if ok else 1
    with atomic_write(args.out) as handle:
        handle.write(text)
    readme = Path(__file__).resolve().parent.parent / "README.md"  # the first table, between its markers
    page = readme.read_text(encoding="utf-8")
    if README_BEGIN in page and README_END in page:
        head, rest = page.split(README_BEGIN, 1)
        table = "\n".join(text.split("\n")[4:6 + len(runs)]) + "\n"
        with atomic_write(readme) as handle:
            handle.write(f"{head}{README_BEGIN}\n{table}{README_END}{rest.split(README_END, 1)[1]}")
    print(f"written to {args.out}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
