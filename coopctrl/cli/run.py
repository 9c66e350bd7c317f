"""``coopctrl run``: simulate a scenario and print its summary."""

from __future__ import annotations

import sys

from coopctrl.cli._core import (PROG, _add_set_option, _load, _one_line, output_directory, stdout_to_stderr,
                                subcommand)
from coopctrl.errors import DivergenceError, InfeasibleLoad

def _simulate_function():
    """The simulator (imported lazily: it pulls in numpy, numba and the solvers)."""
    from coopctrl.simulator import simulate

    return simulate


def cmd_run(args) -> int:
    """Load, simulate, print the summary, save and plot with ``--out``."""
    import json

    import numpy as np

    scenario = _load(args)
    if not args.no_preflight:  # an impossible task is refused before the first tick (exit 1)
        from coopctrl.analysis.preflight import preflight

        report = preflight(scenario)
        if not report.ok:
            print(f"{PROG}: failed: pre-flight: {_one_line(report.issues[0].message)} "
                  "(--no-preflight runs it anyway)", file=sys.stderr)
            return 1
    simulate = _simulate_function()
    progress = not (args.quiet or args.json) and sys.stderr.isatty()
    try:
        with stdout_to_stderr(args.json):  # stdout holds the JSON only, whatever a library prints
            result = simulate(scenario, progress=progress)
            with np.errstate(over="ignore", invalid="ignore"):  # a diverged run's figures overflow: it says so
                summary = result.summary()
            if args.out is not None:
                result.save(args.out)
                result.plot(args.out)
                from coopctrl.replay import write_replay

                write_replay(result, scenario, args.out)  # replay.html and scenario.toml (for `coopctrl view`)
    except (DivergenceError, InfeasibleLoad) as err:
        kind = "diverged" if isinstance(err, DivergenceError) else "qp_failed"
        print(f"{PROG}: {kind}: {_one_line(err)}", file=sys.stderr)
        return 1
    from coopctrl.results import summary_table

    if args.json:
        print(json.dumps(summary, indent=2, allow_nan=False))
    elif not args.quiet:
        print(summary_table(summary))
        ticks = len(result.t)
        print(f"{'torque-saturated ticks'.ljust(28)}  {summary.get('torque_saturated_ticks', 0)} of {ticks}")
        if args.out is not None:
            print(f"outputs written to {args.out}")
    saturated = int(summary.get("torque_saturated_ticks", 0) or 0)
    if saturated and result.status == "ok":  # a failed run's one-line reason names the saturation when it is a cause
        ratio = summary.get("max_torque_ratio")
        shown = "-" if ratio is None else f"{ratio:.3g}"
        print(f"{PROG}: warning: the torques saturated at tau_max on {saturated} of {len(result.t)} ticks "
              f"(max |tau| / tau_max = {shown})", file=sys.stderr)
    if result.status != "ok":
        print(f"{PROG}: {result.status}: {_one_line(result.reason) or 'no reason given'}", file=sys.stderr)
        return 1
    return 0


@subcommand
def _run_parser(sub) -> None:
    parser = sub.add_parser(
        "run",
        help="simulate a scenario and print its summary",
        description="Check the task along its nominal trajectory (pre-flight, as `coopctrl check`), simulate the "
        "scenario (default: the built-in default scene) and print a summary table. Exit 0 if the run is ok, 1 if "
        "pre-flight found the task impossible or the run diverged or the load distribution failed, 2 for bad input.",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file, or the name of one in scenarios/ (default: built-in default scene)")
    _add_set_option(parser)
    parser.add_argument("--out", type=output_directory, metavar="DIR", help="write result.npz, result.csv, summary.json, PNG plots, replay.html (3-D replay) and scenario.toml into DIR")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON on stdout (nothing else on stdout)")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary table")
    parser.add_argument("--no-preflight", action="store_true",
                        help="skip the pre-flight check of the task (see `coopctrl check`) and simulate anyway")
    parser.set_defaults(handler=cmd_run)
