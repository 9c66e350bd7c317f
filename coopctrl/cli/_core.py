"""Shared parts of the command line: the subcommand registry, the parser whose errors are
exceptions, scenario resolution and ``--set`` parsing."""

from __future__ import annotations

import argparse
import os
import sys
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator, Sequence

from coopctrl.errors import CoopctrlError, ScenarioError

PROG = "coopctrl"

#: The subcommands' parser builders by name, in the order of ``--help`` (:func:`subcommand` registers them).
SUBCOMMANDS: dict[str, Callable[[argparse._SubParsersAction], None]] = {}


class UsageError(CoopctrlError, ValueError):
    """Bad command-line usage (unknown option, ``--set`` without ``=``, ...)."""


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill PID``) received: raised in the main thread like Ctrl-C, so that every clean-up that
    Ctrl-C runs (temporary files, sweep workers, the finished sweep rows) also runs; exit 143."""

    def __init__(self, signum: int):
        self.signum = signum
        super().__init__(f"terminated by signal {signum}")


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are exceptions, so that :func:`main` prints one line."""

    def error(self, message: str):  # noqa: D102 - argparse API
        raise UsageError(f"{message}; see `{self.prog} --help`")

    def _print_message(self, message, file=None):  # argparse's own (no public hook) drops a refused write
        """Write argparse's message (``--help``) to ``file``: standard output (``None`` when it was closed at
        start-up) through :func:`~coopctrl.io.console.say`, so that a write the system refuses (a full disk, a
        closed stream, a reader that stopped) is an :class:`~coopctrl.io.console.OutputWriteError`, not a silent
        exit 0; another stream as argparse writes it."""
        if not message:
            return
        from coopctrl.io.console import refused, say

        if file is None or file is sys.stdout:
            say(message[:-1] if message.endswith("\n") else message)
            return
        try:
            file.write(message)
        except (OSError, ValueError) as exc:
            raise refused(file, exc, False) from None


def subcommand(name: str):
    """Register the function that adds the subcommand ``name`` (``sub.add_parser(name, ...)`` and
    ``set_defaults(handler=...)``). A command line that starts with ``name`` builds that parser alone
    (:func:`coopctrl.cli.build_parser`)."""

    def register(configure: Callable[[argparse._SubParsersAction], None]):
        SUBCOMMANDS[name] = configure
        return configure

    return register


def scenarios_dir() -> Path:
    """The folder of the built-in scenarios: ``scenarios/`` of a checkout, or the installed package data
    (:func:`coopctrl.scenario.library.builtin_dir`)."""
    from coopctrl.scenario.library import builtin_dir

    return builtin_dir()


def resolve_scenario(argument: str) -> Path:
    """A path as given if it exists, else a built-in scenario by file name or stem
    (``coopctrl run two_arm_lift``), else the path as given (load reports it missing)."""
    from coopctrl.scenario.library import resolve

    return resolve(argument)


def parse_sets(items: Sequence[str] | None) -> dict[str, str]:
    """``["simulation.integrator=rk4", ...]`` to ``{"simulation.integrator": "rk4", ...}``.

    Raises:
        UsageError: an item without ``=``, or with a control character or a lone surrogate (text that
            is not UTF-8) in its path or value (:mod:`coopctrl.scenario.text`).
    """
    from coopctrl.scenario.text import ALLOWED, bad_character, printable

    overrides: dict[str, str] = {}
    for item in items or ():
        bad = bad_character(item)
        if bad is not None:
            raise UsageError(f"--set '{printable(item)}' is invalid: expected {ALLOWED}; found {bad}")
        path, sep, value = item.partition("=")
        if not sep or not path.strip():
            raise UsageError(f"--set {item!r} is invalid: expected PATH=VALUE, e.g. --set simulation.integrator=rk4")
        overrides[path.strip()] = value.strip()
    return overrides


def int_range(low: int, high: int, meaning: str = ""):
    """An ``argparse`` type: an integer in ``low..high`` (documented in the option's help), else a usage
    error naming the value and the range (exit 2). Every count an option takes has such a range, so that
    no option can ask for endless work (``--calls 1e12``)."""
    def parse(text: str) -> int:
        try:
            value = int(text, 10)
        except (TypeError, ValueError):
            value = None
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text!r} is invalid: expected an integer in {low}..{high}{meaning}")
        return value

    parse.__name__ = "integer"
    return parse


def float_range(low: float, high: float, unit: str = "", meaning: str = ""):
    """An ``argparse`` type: a finite number ``low < x <= high`` [``unit``], else a usage error (exit 2)."""
    def parse(text: str) -> float:
        try:
            value = float(text)
        except (TypeError, ValueError):
            value = float("nan")
        if not low < value <= high:  # NaN fails both comparisons
            raise argparse.ArgumentTypeError(f"{text!r} is invalid: expected a number > {low:g} and <= {high:g}"
                                             f"{' ' + unit if unit else ''}{meaning}")
        return value

    parse.__name__ = "number"
    return parse


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
    scenario = load_scenario(path, parse_sets(args.sets))
    try:  # a URDF arm's file is read now (safely, in pure Python: plants.urdf_reader), before any long work
        scenario.dof_per_arm  # noqa: B018
    except ScenarioError as err:
        if err.source or scenario.source is None:
            raise
        raise ScenarioError(err.path, err.value, err.allowed, scenario.source) from None
    return scenario


def refuse_before_work(scenario) -> None:
    """The refusals of a valid scene that ``run`` and ``check`` both make before any long work, with the
    same line (exit 2): a record that cannot fit in memory (a lower bound: the state and the torques of every
    tick, :func:`coopctrl.record_memory.check_record_fits`) and a nominal path through the Euler-angle band
    (:func:`coopctrl.scenario.build.check_path`)."""
    from coopctrl.record_memory import check_record_fits
    from coopctrl.scenario.build import check_path

    sim = scenario.simulation  # before pre-flight, whose cost grows with the duration
    check_record_fits(int(round(sim.duration / sim.control_period)) + 1, scenario.state_size + sum(scenario.dof_per_arm),
                      sim.duration, sim.control_period)
    check_path(scenario)


def refuse_record(scenario, loop) -> None:
    """The exact record check that the loop makes before its first tick (``ClosedLoop.run``), for ``check``
    (which builds the loop but does not run it): same condition, same line."""
    import numpy as np

    from coopctrl.record_memory import check_record_fits

    sim = scenario.simulation
    floats = sum(v[:1].size for v in loop.empty_record(1).values() if isinstance(v, np.ndarray))
    check_record_fits(int(round(sim.duration / loop.T)) + 1, floats, sim.duration, loop.T)


def preflight_line(report) -> str:
    """The one line of a pre-flight refusal, the same for ``run`` and ``check`` (after ``coopctrl: failed:``)."""
    return f"pre-flight: {one_line(report.issues[0].message)}"


def one_line(text) -> str:
    """``text`` on one line, with every character a terminal would act on or hide escaped (control
    characters, bidirectional overrides, lone surrogates: :func:`coopctrl.io.console.visible`): a message
    quoting user input or a path must not drive the terminal."""
    from coopctrl.io.console import visible

    return visible(" ".join(str(text).splitlines()).strip())


_one_line = one_line  # the name the subcommand modules import


def output_directory(text: str) -> Path:
    """The ``--out DIR`` of a subcommand, checked before any work (an ``argparse`` type: a bad place is a
    usage error, exit 2). An existing directory is accepted (its files of the same names are replaced);
    a missing one must be creatable (:func:`coopctrl.io.output_folder.check_writable`, which leaves
    nothing behind).

    Raises:
        argparse.ArgumentTypeError: ``text`` is an existing non-directory (a file, ``/dev/null``), or a
            place where a directory cannot be created or written (``/proc/x``, a read-only mount).
    """
    path = Path(text).expanduser()
    allowed = "a new or existing writable directory"
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: it exists and is not a directory; expected {allowed}")
    from coopctrl.io.output_folder import check_writable

    try:
        check_writable(text, path, allowed)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return path


@contextmanager
def stdout_to_stderr(enabled: bool = True) -> Iterator[None]:
    """Send everything written to file descriptor 1 to stderr while the block runs: Python's prints and
    C libraries that write to stdout themselves (LAPACK's "** On entry to DLASCL" messages), also in
    worker processes started inside the block. ``--json`` wraps its computation in it, so that stdout
    carries the JSON document and nothing else."""
    if not enabled:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        try:
            sys.stdout.flush()
        finally:
            os.dup2(saved, 1)
            os.close(saved)
