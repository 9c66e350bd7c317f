"""Shared parts of the command line: the subcommand registry, the parser whose errors are
exceptions, scenario resolution and ``--set`` parsing."""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator, Sequence

from coopctrl.errors import CoopctrlError, ScenarioError

PROG = "coopctrl"

#: Functions that each add one subcommand to the subparsers, in the order of ``--help``.
SUBCOMMANDS: list[Callable[[argparse._SubParsersAction], None]] = []


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
    scenario = load_scenario(path, parse_sets(args.sets))
    try:  # a URDF arm's file is read now (safely, without numba: plants.urdf_reader), before any long work
        scenario.dof_per_arm  # noqa: B018
    except ScenarioError as err:
        if err.source or scenario.source is None:
            raise
        raise ScenarioError(err.path, err.value, err.allowed, scenario.source) from None
    return scenario


def _one_line(text: str) -> str:
    return " ".join(str(text).splitlines()).strip()


def output_directory(text: str) -> Path:
    """The ``--out DIR`` of a subcommand, checked before any work (an ``argparse`` type: a bad place is a
    usage error, exit 2). An existing directory is accepted (its files of the same names are replaced);
    a missing one must be creatable. The check creates the missing directories and a probe file, then
    removes them again, so that it leaves nothing behind and says exactly what the system refused.

    Raises:
        argparse.ArgumentTypeError: ``text`` is an existing non-directory (a file, ``/dev/null``), or a
            place where a directory cannot be created or written (``/proc/x``, a read-only mount).
    """
    path = Path(text).expanduser()
    allowed = "a new or existing writable directory"
    if path.exists() and not path.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: it exists and is not a directory; expected {allowed}")
    created: list[Path] = []
    try:
        missing = []
        parent = path
        while not parent.exists():
            missing.append(parent)
            if parent.parent == parent:
                break
            parent = parent.parent
        if parent.exists() and not parent.is_dir():
            raise argparse.ArgumentTypeError(f"{text!r} is invalid: {str(parent)!r} is not a directory; expected {allowed}")
        for directory in reversed(missing):
            directory.mkdir()
            created.append(directory)
        fd, probe = tempfile.mkstemp(dir=path, prefix=".coopctrl-probe.", suffix=".tmp")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise argparse.ArgumentTypeError(f"{text!r} is invalid: cannot write there ({reason}); expected {allowed}") from None
    finally:
        for directory in reversed(created):
            try:
                directory.rmdir()
            except OSError:
                pass
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
