"""The ``coopctrl`` command line: ``run``, ``list``, ``check`` (and more to come).

Exit codes: 0 success; 1 the run ended with status ``"diverged"`` or ``"qp_failed"`` (one line on
stderr says why); 2 bad input or usage (one line ``coopctrl: error: ...`` on stderr, never a
traceback); 130 interrupted (Ctrl-C).

Adding a subcommand is one function decorated with :func:`subcommand`: it adds its parser to
the subparsers and sets ``handler`` (``args -> int``). Keep start-up fast: numpy, matplotlib,
control and the simulator are imported inside the handlers, never at module import.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Callable, Sequence

from coopctrl.errors import CoopctrlError, DivergenceError, InfeasibleLoad

PROG = "coopctrl"

#: Functions that each add one subcommand to the subparsers, in the order of ``--help``.
SUBCOMMANDS: list[Callable[[argparse._SubParsersAction], None]] = []


class UsageError(CoopctrlError, ValueError):
    """Bad command-line usage (unknown option, ``--set`` without ``=``, ...)."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are exceptions, so that :func:`main` prints one line."""

    def error(self, message: str):  # noqa: D102 - argparse API
        raise UsageError(f"{message}; see `{self.prog} --help`")


def subcommand(configure: Callable[[argparse._SubParsersAction], None]):
    """Register a function that adds a subcommand (``sub.add_parser(...)`` and
    ``set_defaults(handler=...)``)."""
    SUBCOMMANDS.append(configure)
    return configure


def scenarios_dir() -> Path:
    """The directory of the built-in scenarios, ``scenarios/`` at the repository root."""
    import coopctrl

    return Path(coopctrl.__file__).resolve().parent.parent / "scenarios"


def resolve_scenario(argument: str) -> Path:
    """A path as given if it exists, else a built-in scenario by file name or stem
    (``coopctrl run two_arm_lift``), else the path as given (load reports it missing)."""
    path = Path(argument)
    if path.exists():
        return path
    for candidate in (scenarios_dir() / argument, scenarios_dir() / f"{argument}.toml"):
        if candidate.is_file():
            return candidate
    return path


def parse_sets(items: Sequence[str] | None) -> dict[str, str]:
    """``["simulation.integrator=rk4", ...]`` to ``{"simulation.integrator": "rk4", ...}``."""
    overrides: dict[str, str] = {}
    for item in items or ():
        path, sep, value = item.partition("=")
        if not sep or not path.strip():
            raise UsageError(f"--set {item!r} is invalid: expected PATH=VALUE, e.g. --set simulation.integrator=rk4")
        overrides[path.strip()] = value.strip()
    return overrides


def _add_set_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--set",
        dest="sets",
        action="append",
        default=[],
        metavar="PATH=VALUE",
        help="override a field by its dotted path, value in TOML syntax "
        "(--set simulation.integrator=rk4 --set 'springs[0].stiffness=1e6' --set 'arms[1].grasp=[0.1,0,3.14]'); repeatable",
    )


def _load(args):
    from coopctrl.scenario import load_scenario

    path = resolve_scenario(args.scenario) if args.scenario else None
    return load_scenario(path, parse_sets(args.sets))


def _one_line(text: str) -> str:
    return " ".join(str(text).splitlines()).strip()


# ---------------------------------------------------------------------- run
def _simulate_function():
    """The simulator (imported lazily: it pulls in numpy, numba and the solvers)."""
    from coopctrl.simulator import simulate

    return simulate


def cmd_run(args) -> int:
    """Load, simulate, print the summary, save and plot with ``--out``."""
    import json

    scenario = _load(args)
    simulate = _simulate_function()
    progress = not (args.quiet or args.json) and sys.stderr.isatty()
    try:
        result = simulate(scenario, progress=progress)
    except (DivergenceError, InfeasibleLoad) as err:
        kind = "diverged" if isinstance(err, DivergenceError) else "qp_failed"
        print(f"{PROG}: {kind}: {_one_line(err)}", file=sys.stderr)
        return 1
    from coopctrl.results import summary_table

    summary = result.summary()
    if args.out is not None:
        result.save(args.out)
        result.plot(args.out)
    if args.json:
        print(json.dumps(summary, indent=2, allow_nan=False))
    elif not args.quiet:
        print(summary_table(summary))
        if args.out is not None:
            print(f"outputs written to {args.out}")
    if result.status != "ok":
        print(f"{PROG}: {result.status}: {_one_line(result.reason) or 'no reason given'}", file=sys.stderr)
        return 1
    return 0


@subcommand
def _run_parser(sub) -> None:
    parser = sub.add_parser(
        "run",
        help="simulate a scenario and print its summary",
        description="Simulate a scenario (default: the built-in default scene) and print a summary table. "
        "Exit 0 if the run is ok, 1 if it diverged or the load distribution failed, 2 for bad input.",
    )
    parser.add_argument("scenario", nargs="?", help="scenario .toml file, or the name of one in scenarios/ (default: built-in default scene)")
    _add_set_option(parser)
    parser.add_argument("--out", type=Path, metavar="DIR", help="write result.npz, result.csv, summary.json and PNG plots into DIR")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON on stdout (nothing else on stdout)")
    parser.add_argument("--quiet", "-q", action="store_true", help="no progress bar and no summary table")
    parser.set_defaults(handler=cmd_run)


# ---------------------------------------------------------------------- list
def cmd_list(args) -> int:
    """Print the scenarios of the directory with their descriptions."""
    import tomllib

    directory = Path(args.dir) if args.dir else scenarios_dir()
    files = sorted(directory.glob("*.toml"))
    if not files:
        print(f"no scenarios in {directory}", file=sys.stderr)
        return 0
    rows = []
    for path in files:
        try:
            description = tomllib.loads(path.read_text(encoding="utf-8")).get("description", "")
            description = _one_line(description) if isinstance(description, str) else ""
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as err:
            description = f"(unreadable: {_one_line(err)})"
        rows.append((path.stem, description))
    width = max(len(name) for name, _ in rows)
    for name, description in rows:
        print(f"{name.ljust(width)}  {description}".rstrip())
    return 0


@subcommand
def _list_parser(sub) -> None:
    parser = sub.add_parser("list", help="list the built-in scenarios", description="List the scenarios (scenarios/*.toml) with their descriptions.")
    parser.add_argument("--dir", metavar="DIR", help="list DIR instead of the built-in scenarios directory")
    parser.set_defaults(handler=cmd_list)


# ---------------------------------------------------------------------- check
def cmd_check(args) -> int:
    """Validate a scenario without simulating it: its fields, then the physics it implies (every grasp
    within reach, torque limits above the arms' own gravity load, the loaded initial state)."""
    scenario = _load(args)
    scenario.plant()
    scenario.initial_state()
    print(
        f"ok: {scenario.name} ({scenario.space}, {len(scenario.arms)} arms, state size {scenario.state_size}, "
        f"{scenario.simulation.control_steps} control steps of {scenario.simulation.control_period:g} s)"
    )
    return 0


@subcommand
def _check_parser(sub) -> None:
    parser = sub.add_parser(
        "check", help="validate a scenario file", description="Validate a scenario (and overrides) without simulating. Exit 0 if valid, 2 if not."
    )
    parser.add_argument("scenario", help="scenario .toml file, or the name of one in scenarios/")
    _add_set_option(parser)
    parser.set_defaults(handler=cmd_check)


# ---------------------------------------------------------------------- main
def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand."""
    parser = _Parser(
        prog=PROG,
        description="Simulation and control of several robot arms carrying one object through elastic grasps.",
        epilog="Exit codes: 0 ok, 1 run diverged or QP failed, 2 bad input, 130 interrupted.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for configure in SUBCOMMANDS:
        configure(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code."""
    try:
        args = build_parser().parse_args(argv)
        return int(args.handler(args))
    except SystemExit as exit_:  # --help / --version
        return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 2)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except (DivergenceError, InfeasibleLoad) as err:
        print(f"{PROG}: failed: {_one_line(err)}", file=sys.stderr)
        return 1
    except CoopctrlError as err:
        print(f"{PROG}: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0


if __name__ == "__main__":
    sys.exit(main())
