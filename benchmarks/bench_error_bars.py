"""The printed error bar (``coopctrl run --estimate-error``) against the error measured against an independent
reference, per scheme and scene: the table of docs/speed-accuracy.md.

For each scene and scheme (``rk45``, ``trbdf2``, ``rk23`` at the scene's tolerances; ``rk4`` at its step), over
``--duration`` simulated seconds:

* the bar: :func:`coopctrl.analysis.error_estimate.estimate_error` (what ``--estimate-error`` prints);
* the actual error: the same run against scipy's DOP853 at rtol 1e-11, atol 1e-12 (the ``coopctrl tradeoff``
  reference, :class:`coopctrl.analysis.reference.ReferenceIntegrator`: another method than either the run
  or the bar's RK4 reference);
* their ratio, bar / actual, for the object position [m] and the contact forces [N] (maxima over the run).

Writes ``docs/data/error_bars.csv`` and ``docs/data/error_bars.md`` (the table), and puts the table into
``docs/speed-accuracy.md`` between its ``error_bars`` markers: the figures are never typed by hand.

    python benchmarks/bench_error_bars.py [--duration 0.2] [--scenes stiff_grasp_extreme,spatial_two_puma_carry]
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DATA = REPO / "docs" / "data"
DOC = REPO / "docs" / "speed-accuracy.md"
BEGIN, END = "<!-- error_bars:begin (benchmarks/bench_error_bars.py) -->", "<!-- error_bars:end -->"
SCHEMES = ("rk45", "trbdf2", "rk23", "rk4")
COLUMNS = ("scene", "integrator", "setting", "bar_position_m", "actual_position_m", "ratio_position",
           "bar_force_N", "actual_force_N", "ratio_force", "duration_s")


def measure(name: str, scheme: str, duration: float) -> dict:
    import coopctrl
    from coopctrl.analysis.error_estimate import estimate_error
    from coopctrl.analysis.reference import ReferenceConfig, ReferenceIntegrator
    from coopctrl.analysis.tradeoff import run_errors, run_loop
    from coopctrl.integrators import get_integrator
    from coopctrl.scenario import build

    scene = coopctrl.load_scenario(REPO / "scenarios" / f"{name}.toml",
                                   {"simulation.integrator": scheme, "simulation.duration": duration})
    sim = scene.simulation
    bar = estimate_error(scene)
    x0 = build.initial_state(scene)
    cheap = (get_integrator(scheme, rtol=sim.rtol, atol=sim.atol, atol_velocity=sim.atol_velocity,
                            min_step=sim.min_step) if sim.adaptive else get_integrator(scheme))
    run = run_loop(scene, x0, cheap, 1 if sim.adaptive else sim.substeps, duration)
    ref = run_loop(scene, x0, ReferenceIntegrator(ReferenceConfig()), 1, duration)
    actual = run_errors(run, ref)

    def ratio(b, a):
        return None if b is None or not a else b / a

    return {"scene": name, "integrator": scheme, "setting": bar.setting,
            "bar_position_m": bar.position_m, "actual_position_m": actual["position_error_m"],
            "ratio_position": ratio(bar.position_m, actual["position_error_m"]),
            "bar_force_N": bar.force_N, "actual_force_N": actual["force_error_N"],
            "ratio_force": ratio(bar.force_N, actual["force_error_N"]), "duration_s": duration}


def _g(v) -> str:
    return "-" if v is None else f"{v:.3g}"


def table(rows: list[dict]) -> str:
    lines = ["| scene | scheme | setting | bar, position | actual | bar / actual | bar, force | actual | bar / actual |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['integrator']} | {r['setting']} | {_g(r['bar_position_m'])} m | "
                     f"{_g(r['actual_position_m'])} m | {_g(r['ratio_position'])} | {_g(r['bar_force_N'])} N | "
                     f"{_g(r['actual_force_N'])} N | {_g(r['ratio_force'])} |")
    d = rows[0]["duration_s"] if rows else 0
    lines.append("")
    lines.append(f"({d:g} s simulated per run; actual: against DOP853 at rtol 1e-11, atol 1e-12.)")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=0.2, help="simulated time per run [s] (default 0.2)")
    parser.add_argument("--scenes", default="stiff_grasp_extreme,spatial_two_puma_carry")
    parser.add_argument("--schemes", default=",".join(SCHEMES))
    args = parser.parse_args(argv)
    if not 0 < args.duration <= 10:
        parser.error(f"--duration {args.duration} is invalid: expected 0 < duration <= 10 s")
    rows = []
    for name in [s for s in args.scenes.split(",") if s]:
        for scheme in [s for s in args.schemes.split(",") if s]:
            row = measure(name, scheme, args.duration)
            print(f"{name} {scheme}: bar {_g(row['bar_position_m'])} m, actual {_g(row['actual_position_m'])} m, "
                  f"ratio {_g(row['ratio_position'])}; force ratio {_g(row['ratio_force'])}", file=sys.stderr)
            rows.append(row)
    DATA.mkdir(parents=True, exist_ok=True)
    with open(DATA / "error_bars.csv", "w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r[k] is None else r[k]) for k in COLUMNS})
    text = table(rows)
    (DATA / "error_bars.md").write_text(text, encoding="utf-8")
    doc = DOC.read_text(encoding="utf-8")
    if BEGIN in doc and END in doc:
        head, rest = doc.split(BEGIN, 1)
        DOC.write_text(f"{head}{BEGIN}\n{text}{END}{rest.split(END, 1)[1]}", encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
