"""The ``coopctrl`` command line: one subcommand per module of this package.

Exit codes: 0 success; 1 the run ended with status ``"diverged"`` or ``"qp_failed"``, or pre-flight
(``check``, and ``run`` before its first tick) found the task impossible (one line on stderr says why); 2 bad input or usage (one line ``coopctrl: error: ...`` on stderr, never a
traceback); 130 interrupted (Ctrl-C).

Adding a subcommand is one module with a function decorated with :func:`subcommand`: it adds its parser to
the subparsers and sets ``handler`` (``args -> int``), imported below. Keep start-up fast: numpy, matplotlib,
control and the simulator are imported inside the handlers, never at module import.
"""

from __future__ import annotations

import argparse
import sys
from typing import Sequence

from coopctrl.cli._core import (PROG, SUBCOMMANDS, UsageError, _Parser, _one_line, parse_sets,  # noqa: F401 (API)
                                resolve_scenario, scenarios_dir, subcommand)
from coopctrl.errors import CoopctrlError, DivergenceError, InfeasibleLoad

# Each module registers its subcommand on import, in the order of ``--help``.
from coopctrl.cli import run as _run  # noqa: E402,F401
from coopctrl.cli import list_scenarios as _list  # noqa: E402,F401
from coopctrl.cli import check as _check  # noqa: E402,F401
from coopctrl.cli import tradeoff as _tradeoff  # noqa: E402,F401
from coopctrl.cli import sweep as _sweep  # noqa: E402,F401
from coopctrl.cli import fidelity as _fidelity  # noqa: E402,F401
from coopctrl.cli import stability as _stability  # noqa: E402,F401


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand."""
    parser = _Parser(
        prog=PROG,
        description="Simulation and control of several robot arms carrying one object through elastic grasps.",
        epilog="Exit codes: 0 ok, 1 run diverged or QP failed or the task is impossible (pre-flight), 2 bad input, "
        "130 interrupted.",
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
