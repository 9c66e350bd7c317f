"""``coopctrl fidelity``: the model-fidelity trade, one task simulated with models of increasing fidelity."""

from __future__ import annotations

import sys

from coopctrl.cli._core import (PROG, UsageError, _add_set_option, _one_line, int_range, output_directory, parse_sets,
                                resolve_scenario, stdout_to_stderr, subcommand)

#: Largest ``--repeats`` (closed-loop runs per model) and ``--calls`` (timed right-hand-side calls per
#: model, 200 times the default): bounds so that no option asks for endless work.
MAX_REPEATS = 100
MAX_CALLS = 1_000_000
#: Most scenes compared in one call.
MAX_SCENES = 16

#: The scenes compared by default: one task as a planar scene, spatial contact points, spatial arms.
DEFAULT_SCENARIOS = ("fidelity_planar", "fidelity_contact_points", "fidelity_spatial_arms")


def cmd_fidelity(args) -> int:
    """Load the scenes (with the same ``--set`` overrides), compare them, print and save the report."""
    import json

    from coopctrl.io.console import say, visible, visible_lines
    from coopctrl.scenario import load_scenario

    names = args.scenarios or list(DEFAULT_SCENARIOS)
    if len(names) > MAX_SCENES:
        raise UsageError(f"fidelity compares at most {MAX_SCENES} scenes (got {len(names)})")
    if len(names) < 2:
        raise UsageError(f"fidelity needs at least two scenes of one task (got {len(names)}: {', '.join(names)}); "
                         f"default: {' '.join(DEFAULT_SCENARIOS)}")
    overrides = parse_sets(args.sets)
    scenarios = [load_scenario(resolve_scenario(name), overrides) for name in names]
    from coopctrl.analysis.fidelity import compare_fidelity

    def progress(message: str) -> None:  # stderr, so that --json keeps stdout clean
        print(f"{PROG} fidelity: {message}", file=sys.stderr, flush=True)

    with stdout_to_stderr(args.json):  # stdout holds the JSON only, whatever a library prints
        report = compare_fidelity(scenarios, repeats=args.repeats, rhs_calls=args.calls,
                                  progress=None if args.quiet else progress)
    if args.out is not None:
        report.save(args.out)
    if args.json:
        say(json.dumps(report.to_dict(), indent=2, allow_nan=False))
    else:
        say(visible_lines(report.table()))
        if args.out is not None:
            say(f"outputs written to {visible(args.out)}")
    failed = [m for m in report.models if m.status != "ok"]
    for m in failed:
        print(f"{PROG}: {visible(m.scenario)}: {m.status}: {_one_line(m.reason) or 'no reason given'}", file=sys.stderr)
    return 1 if failed else 0


@subcommand("fidelity")
def _fidelity_parser(sub) -> None:
    parser = sub.add_parser(
        "fidelity",
        help="one task as planar, contact-point and full spatial scenes: cost and difference in outcome",
        description="Simulate scenes that describe the same task with models of different fidelity and report, "
        "side by side, their cost (state size, joints per arm, right-hand-side time, closed-loop wall time and "
        "real-time factor) and how far their outcome is from the highest-fidelity model in the vertical x-z plane "
        "(object position and angle, contact forces and moments, squeeze). Spatial results are mapped into the "
        "plane as (x, z, theta_p = -pitch) and wrenches as (f_x, f_z, -n_y). Exit 0 if every run is ok, 1 if one "
        "diverged or its load distribution failed, 2 for bad input (also scenes of different tasks).",
    )
    parser.add_argument("scenarios", nargs="*", metavar="SCENARIO",
                        help=f"scenario .toml files or names in scenarios/ (default: {' '.join(DEFAULT_SCENARIOS)})")
    _add_set_option(parser)
    parser.add_argument("--json", action="store_true", help="print the report as JSON on stdout (nothing else on stdout)")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress lines on stderr")
    parser.add_argument("--out", type=output_directory, metavar="DIR",
                        help="write fidelity.json and fidelity_traces.npz (the runs mapped into the plane) into DIR")
    parser.add_argument("--repeats", type=int_range(1, MAX_REPEATS), default=1, metavar="N",
                        help=f"closed-loop runs per model, 1..{MAX_REPEATS}; the wall time is their median (default 1)")
    parser.add_argument("--calls", type=int_range(1, MAX_CALLS), default=5000, metavar="N",
                        help=f"timed right-hand-side calls per model, 1..{MAX_CALLS} (default 5000)")
    parser.set_defaults(handler=cmd_fidelity)
