"""``coopctrl tradeoff``: speed against accuracy of the integrators, against a reference solution."""

from __future__ import annotations

import sys

from coopctrl.cli._core import (PROG, UsageError, _add_set_option, _load, _one_line, int_range,
                                output_directory, stdout_to_stderr, subcommand)
from coopctrl.errors import ScenarioError
from coopctrl.io.console import say, visible, visible_lines

#: Reference methods offered on the command line (see coopctrl.analysis.reference; kept here as
#: plain strings so that the parser does not import numpy).
_METHODS = ("DOP853", "Radau")


#: Largest ``--repeat`` (runs per grid point) and number of ``--steps`` entries (each a column of runs).
MAX_REPEAT = 100
MAX_STEPS = 64


def _count_steps(items) -> None:
    """Refuse more than :data:`MAX_STEPS` ``--steps`` entries before any is parsed."""
    count = sum(len([t for t in str(item).split(",") if t.strip()]) for item in items)
    if count > MAX_STEPS:
        raise UsageError(f"--steps has {count} entries: expected at most {MAX_STEPS} steps")


def _bounded(low: float, high: float, unit: str, meaning: str):
    """An ``argparse`` type: a finite number in ``[low, high]`` [``unit``], else a usage error (exit 2).
    (The ranges are :data:`coopctrl.analysis.accuracy_target.TARGET_RANGE_M` and ``FORCE_TARGET_RANGE_N``,
    repeated here so that the parser does not import numpy; tests/test_accuracy_target.py checks they agree.)"""
    import argparse

    def parse(text: str) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            value = float("nan")
        if not low <= value <= high:  # NaN fails
            raise argparse.ArgumentTypeError(f"{text!r} is invalid: expected {meaning} in [{low:g}, {high:g}] {unit}")
        return value

    parse.__name__ = "number"
    return parse


#: ``--target`` [m] and ``--force-target`` [N] ranges (see :func:`_bounded`).
TARGET_RANGE_M = (1e-12, 1.0)
FORCE_TARGET_RANGE_N = (1e-9, 1e6)


def _print_progress(label: str) -> None:
    print(f"\r{PROG} tradeoff: {label:<32}", end="", file=sys.stderr, flush=True)


def _target_search(args, scenario, integrators, reference, progress) -> int:
    """``--target``: the cheapest setting meeting it on the prefix (coopctrl.analysis.accuracy_target)."""
    import json

    from coopctrl.analysis.accuracy_target import TargetUnreachable, recommend
    from coopctrl.analysis.tradeoff import ReferenceFailed

    try:
        with stdout_to_stderr(args.json):
            search = recommend(scenario, args.target, args.force_target, integrators, reference=reference,
                               progress=progress)
    except ReferenceFailed as err:
        print(f"{PROG}: failed: {_one_line(err)}", file=sys.stderr)
        return 1
    finally:
        if progress is not None:
            print("\r" + " " * 52 + "\r", end="", file=sys.stderr, flush=True)
    if args.json:
        say(json.dumps(search.to_dict(), indent=2, allow_nan=False))
    if search.recommendation is None:
        print(f"{PROG}: failed: {_one_line(TargetUnreachable(search))}", file=sys.stderr)
        return 1
    if not (args.json or args.quiet):
        say(visible_lines(search.text()))
    return 0


def cmd_tradeoff(args) -> int:
    """Run the grid; print the table or the JSON; write the files with ``--out``. With ``--target``,
    search the cheapest setting meeting it instead."""
    import json

    from coopctrl.analysis.reference import ReferenceConfig
    from coopctrl.analysis.tradeoff import ReferenceFailed, parse_integrators, parse_rtols, parse_steps, run_tradeoff

    if args.force_target is not None and args.target is None:
        raise UsageError("--force-target needs --target (the object position error target [m])")
    if args.target is not None and (args.out is not None or args.steps or args.rtols):
        raise UsageError("--target searches its own settings on a prefix of the run: it takes no --steps, --rtols "
                         "or --out")
    scenario = _load(args)
    integrators = parse_integrators(args.integrators) if args.integrators else None
    if args.steps:
        _count_steps(args.steps)
    substeps = parse_steps(args.steps, scenario.simulation.control_period) if args.steps else None
    rtols = parse_rtols(args.rtols) if args.rtols else None
    try:
        reference = ReferenceConfig(args.reference_method, args.reference_rtol, args.reference_atol)
    except ScenarioError as err:  # name the option, not the dataclass field
        raise ScenarioError("--" + err.path.replace(".", "-"), err.value, err.allowed) from None
    progress = _print_progress if not (args.json or args.quiet) and sys.stderr.isatty() else None
    if args.target is not None:
        return _target_search(args, scenario, integrators, reference, progress)
    try:
        with stdout_to_stderr(args.json):  # stdout holds the JSON only, whatever a library prints
            result = run_tradeoff(scenario, integrators, substeps, reference, repeats=args.repeat, progress=progress,
                                  rtols=rtols)
    except ReferenceFailed as err:
        print(f"{PROG}: failed: {_one_line(err)}", file=sys.stderr)
        return 1
    finally:
        if progress is not None:
            print("\r" + " " * 52 + "\r", end="", file=sys.stderr, flush=True)
    if args.out is not None:
        result.save(args.out)
    if args.json:
        say(json.dumps(result.to_dict(), indent=2, allow_nan=False))
    elif not args.quiet:
        say(visible_lines(result.table()))
        if args.out is not None:
            say(f"outputs written to {visible(args.out)}")
    return 0


@subcommand("tradeoff")
def _tradeoff_parser(sub) -> None:
    parser = sub.add_parser(
        "tradeoff",
        help="speed vs accuracy of the integrators against a reference solution (work-precision)",
        description="Simulate the scenario's closed loop with a reference solution (scipy solve_ivp over each "
        "control period, tight tolerances) and with each integrator at each step h = T/n, and report for each run "
        "the error against the reference (object position and orientation, contact forces; maximum over the run), "
        "the wall time, the real-time factor and the status, with the Pareto front of (wall time, error). "
        "The simulated time is the scenario's: shorten it with --set simulation.duration=0.3. "
        "With --target E: measure a short prefix of the run, min(duration, max(0.25 s, 50 control periods)), "
        "against the reference and print the cheapest setting (in plant right-hand-side evaluations) whose "
        "position error times a safety factor meets E, as the --set lines to use. "
        "Exit 0 when the grid ran (rows that diverged are results) or a setting meets the target, 1 if the "
        "reference failed or no setting meets the target, 2 for bad input.",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file or a name in scenarios/ (default: the built-in scene)")
    _add_set_option(parser)
    parser.add_argument("--integrators", action="append", metavar="NAMES",
                        help="comma-separated integrators (default: euler,symplectic_euler,rk4,implicit_midpoint,"
                        "implicit_euler, then the error-controlled rk23,rk45,trbdf2); repeatable")
    parser.add_argument("--steps", action="append", metavar="STEPS",
                        help="comma-separated steps, each in seconds (2.5e-4) or as T/n (T/4), dividing the control "
                        "period T (default: T/1,T/2,T/4,T/8,T/16; n in T/n at most 4096, at most 64 steps); repeatable")
    parser.add_argument("--rtols", action="append", metavar="RTOLS",
                        help="comma-separated relative tolerances of the error-controlled schemes, each in "
                        "[1e-13, 0.1], atol = 0.01 rtol [m] (default: 1e-3 to 1e-9 by decades); repeatable")
    parser.add_argument("--target", type=_bounded(*TARGET_RANGE_M, "m", "an object position error"),
                        metavar="E", help="print the cheapest setting whose object position error meets E [m] "
                        "(measured on a prefix of the run, with a safety factor) instead of the grid")
    parser.add_argument("--force-target", type=_bounded(*FORCE_TARGET_RANGE_N, "N", "a contact force error"),
                        metavar="N", help="with --target: the contact force error must also meet N [N]")
    parser.add_argument("--reference-method", choices=_METHODS, default="DOP853",
                        help="solve_ivp method of the reference (default DOP853; Radau for very stiff scenes)")
    parser.add_argument("--reference-rtol", type=float, default=1e-11, metavar="RTOL",
                        help="relative tolerance of the reference (default 1e-11)")
    parser.add_argument("--reference-atol", type=float, default=1e-12, metavar="ATOL",
                        help="absolute tolerance of the reference, state units (default 1e-12)")
    parser.add_argument("--repeat", type=int_range(1, MAX_REPEAT), default=1, metavar="N",
                        help=f"run each grid point N times, 1..{MAX_REPEAT}, and report the smallest wall time (default 1)")
    parser.add_argument("--out", type=output_directory, metavar="DIR",
                        help="write tradeoff.json, tradeoff.csv and work_precision.png into DIR")
    parser.add_argument("--json", action="store_true", help="print the result as JSON on stdout (nothing else)")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress and no table")
    parser.set_defaults(handler=cmd_tradeoff)
