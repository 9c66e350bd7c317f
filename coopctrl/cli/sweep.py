"""``coopctrl sweep``: the Cartesian product of overrides of one scenario, one summary row per run."""

from __future__ import annotations

import argparse
import sys

from coopctrl.cli._core import (PROG, _add_set_option, float_range, int_range, output_directory, parse_sets,
                                resolve_scenario, stdout_to_stderr, subcommand)
from coopctrl.io.console import say, visible


def worker_function():
    """The function each run of the sweep executes (imported lazily: it pulls in the simulator); a test
    replaces this function to observe or fake the runs."""
    from coopctrl.sweep.worker import simulate_run

    return simulate_run


#: Most local worker processes (``--jobs``) and the longest ``--run-timeout`` [s] (one week).
MAX_JOBS = 256
MAX_RUN_TIMEOUT_S = 604800.0


def _sweep_directory(text: str):
    """``--out DIR`` of ``sweep``: writable, and new, empty or an earlier sweep's folder (it is replaced
    as one unit at each save, :meth:`coopctrl.sweep.SweepResult.save`)."""
    from coopctrl.io.output_folder import SWEEP_FOLDER, check_output_folder

    try:
        return check_output_folder(output_directory(text), SWEEP_FOLDER)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _emit(result, args, written: bool = True) -> None:
    if args.json:
        say(result.to_json())
    elif not args.quiet:
        say(result.table())
        if args.out is not None and written:
            say(f"rows written to {visible(args.out / 'sweep.csv')} and {visible(args.out / 'sweep.json')}")


def cmd_sweep(args) -> int:
    """Validate every combination, run them, print the rows; exit 0 when every run is ok, 1 when a run
    failed (its row says why; a run whose worker died was retried once in a fresh worker first) or the
    output could not be written, 2 for bad input, 130 when interrupted (after saving the finished rows)."""
    from coopctrl.io.console import OutputWriteError
    from coopctrl.sweep import SweepGrid, SweepInterrupted, run_sweep

    grid = SweepGrid.parse(args.grid)
    sets = parse_sets(args.sets)
    progress = not (args.quiet or args.json) and sys.stderr.isatty()
    path = resolve_scenario(args.scenario) if args.scenario else None
    run_function = worker_function()
    try:
        with stdout_to_stderr(args.json):  # stdout holds the JSON only, whatever a library or worker prints
            result = run_sweep(path, grid, sets=sets, jobs=args.jobs, scheduler=args.scheduler,
                               progress=progress, out=args.out, run_function=run_function,
                               run_timeout_s=args.run_timeout)
    except SweepInterrupted as stop:
        partial = stop.result
        _emit(partial, args)
        kept = f"kept in {visible(args.out)}" if args.out is not None else "printed above (use --out DIR to keep them in files)"
        print(f"{PROG}: interrupted: {len(partial.rows)} of {partial.runs} runs finished, {kept}", file=sys.stderr)
        return 130
    except OutputWriteError as err:  # the output refused (a full disk): the rows so far on stdout, one line why
        partial = getattr(err, "partial", None)
        done = ""
        if partial is not None:
            _emit(partial, args, written=False)
            done = f"; the sweep stopped after {len(partial.rows)} of {partial.runs} runs, whose rows are printed above"
        print(f"{PROG}: failed: {err}{done}", file=sys.stderr)
        return 1
    _emit(result, args)
    if result.retried:
        runs = ", ".join(f"run {run} (a worker of its pool {cause})" for run, cause in result.retried)
        print(f"{PROG}: retried in a fresh worker after a worker process died: {runs}", file=sys.stderr)
    if result.failed:
        print(f"{PROG}: {len(result.failed)} of {result.runs} runs failed (see their status and reason)", file=sys.stderr)
        return 1
    return 0


@subcommand("sweep")
def _sweep_parser(sub) -> None:
    parser = sub.add_parser(
        "sweep",
        help="run a scenario over a grid of overrides and tabulate one row per run",
        description="Run the Cartesian product of the --grid values (last --grid varying fastest) and print one summary "
        "row per run. A grid has at most 10000 runs (the product of the axis lengths, counted before anything is expanded); "
        "every combination is validated before any run starts. A failed run (diverged, QP failed, error) "
        "is a row with its reason. Rows do not depend on --jobs except the timing columns (realtime_factor, wall_time_s). "
        "A run whose worker process dies (SIGKILL, a crash, out of memory) is retried once in a fresh worker; the other "
        "runs keep their results. Exit 0 when every run is ok, 1 when a run failed (its row says why) or the output "
        "could not be written, 2 for bad input, 130 when interrupted (the finished rows are kept in --out).",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file or a name in scenarios/ (default: the built-in scene)")
    parser.add_argument(
        "--grid", action="append", default=[], metavar="PATH=V1,V2,...",
        help="sweep a field over values in TOML syntax; values split on commas outside brackets and quotes "
        "(--grid simulation.integrator=rk4,euler --grid 'arms[1].grasp=[0.1,0,3.14],[0.1,0,3.0]'); repeatable",
    )
    _add_set_option(parser)
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--jobs", "-j", type=int_range(1, MAX_JOBS, " (1 runs in this process)"), metavar="N",
                       help=f"local worker processes, 1..{MAX_JOBS} (default: CPU count; 1 runs in this process)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on the Dask cluster of this scheduler, e.g. tcp://scheduler.example:8786 "
                       "(pip install 'coopctrl[distributed]')")
    parser.add_argument("--out", type=_sweep_directory, metavar="DIR", help="write sweep.csv and sweep.json into DIR, updated as runs finish")
    parser.add_argument("--run-timeout", type=float_range(0.0, MAX_RUN_TIMEOUT_S, "s"), metavar="SECONDS",
                        help="stop a run after this wall time (> 0 and <= 604800 s, one week); it becomes a row with "
                        "status 'timeout' "
                        "(local workers and --jobs 1; default: no limit)")
    parser.add_argument("--json", action="store_true", help="print one JSON document {scenario, grid, set, ..., rows} on stdout")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no table")
    parser.set_defaults(handler=cmd_sweep)
