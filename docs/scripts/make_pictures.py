"""Regenerate the documentation's pictures with the code a user runs.

Run: python docs/scripts/make_pictures.py [--only NAME[,NAME...]] [--no-replay]

- ``spatial_two_puma_carry_contact_forces.png`` and ``spatial_two_puma_carry_object_pose.png``: the plots
  ``coopctrl run spatial_two_puma_carry --out DIR`` writes (``coopctrl.results.plots``);
- ``heavy_payload_torque_limits_qp_solve_times.png``: the QP plot of ``coopctrl run
  heavy_payload_torque_limits --out DIR`` (its torque-limit rows bind, so the QP's work varies);
- ``work_precision.png``: the plot ``coopctrl tradeoff planar_two_arm_lift --set simulation.duration=0.2
  --out DIR`` writes;
- ``replay_two_panda_carry.png`` and ``replay_spatial_two_puma_carry.png``: ``replay.html`` of
  ``coopctrl run`` opened at ``#t=1.0`` and ``#t=1.25`` in a headless chromium (skipped, saying so, when no
  chromium is installed: ``apt-get install chromium``).

Each run goes through :func:`coopctrl.cli.main`, as the command line does, into a temporary folder; the
pictures are copied into docs/.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

DOCS = Path(__file__).resolve().parent.parent
REPLAYS = {"two_panda_carry": 1.0, "spatial_two_puma_carry": 1.25}


def _cli(*argv: str) -> None:
    from coopctrl.cli import main

    code = main(list(argv))
    if code != 0:
        raise SystemExit(f"coopctrl {' '.join(argv)} exited {code}")


def carry_plots(work: Path) -> list[Path]:
    out = work / "carry"
    _cli("run", "spatial_two_puma_carry", "--quiet", "--out", str(out))
    made = []
    for name in ("contact_forces.png", "object_pose.png"):
        target = DOCS / f"spatial_two_puma_carry_{name}"
        shutil.copyfile(out / name, target)
        made.append(target)
    return made


def qp_plot(work: Path) -> list[Path]:
    out = work / "heavy"
    _cli("run", "heavy_payload_torque_limits", "--quiet", "--out", str(out))
    target = DOCS / "heavy_payload_torque_limits_qp_solve_times.png"
    shutil.copyfile(out / "qp_solve_times.png", target)
    return [target]


def work_precision(work: Path) -> list[Path]:
    out = work / "tradeoff"
    _cli("tradeoff", "planar_two_arm_lift", "--set", "simulation.duration=0.2", "--quiet", "--out", str(out))
    shutil.copyfile(out / "work_precision.png", DOCS / "work_precision.png")
    return [DOCS / "work_precision.png"]


def replays(work: Path) -> list[Path]:
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    if browser is None:
        print("no chromium on PATH: the replay pictures are left as they are (apt-get install chromium)", file=sys.stderr)
        return []
    made = []
    for scene, t in REPLAYS.items():
        out = work / scene
        _cli("run", scene, "--quiet", "--out", str(out))
        target = DOCS / f"replay_{scene}.png"
        subprocess.run([browser, "--headless", "--no-sandbox", "--window-size=1000,640", f"--screenshot={target}",
                        f"{(out / 'replay.html').as_uri()}#t={t}"], check=True, capture_output=True, timeout=300)
        made.append(target)
    return made


STEPS = {"carry": carry_plots, "qp": qp_plot, "work_precision": work_precision, "replay": replays}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", default=",".join(STEPS), help=f"comma-separated steps among {', '.join(STEPS)}")
    parser.add_argument("--no-replay", action="store_true", help="leave the replay screenshots as they are")
    args = parser.parse_args(argv)
    steps = [s for s in args.only.split(",") if s]
    unknown = [s for s in steps if s not in STEPS]
    if unknown:
        parser.error(f"--only {args.only!r}: unknown step(s) {', '.join(unknown)}; expected {', '.join(STEPS)}")
    if args.no_replay and "replay" in steps:
        steps.remove("replay")
    with tempfile.TemporaryDirectory() as tmp:
        for step in steps:
            for path in STEPS[step](Path(tmp)):
                print(f"wrote {path.relative_to(DOCS.parent)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
