"""The ``coopctrl`` command line: one subcommand per module of this package.

Exit codes: 0 success; 1 the run ended with status ``"diverged"`` or ``"qp_failed"`` (one line on
stderr says why), pre-flight (``check``, and ``run`` before its first tick) found the task impossible,
a numerical failure (overflow, a failed factorization) stopped it, a run of a sweep failed, or the system
refused an output (a full disk, a folder that cannot be written, a closed or full standard output: one line
naming the place and the cause, never "internal error"); 2 bad input or usage (one line
``coopctrl: error: ...`` on stderr, never a traceback); 130 interrupted (Ctrl-C, SIGINT); 143
terminated (SIGTERM). On 130 and 143 no temporary file is left and finished files are whole.

Adding a subcommand is one module with a function decorated with ``@subcommand(NAME)`` (:func:`subcommand`):
it adds its parser to the subparsers and sets ``handler`` (``args -> int``), imported below. Keep start-up
fast: numpy, matplotlib, control and the simulator are imported inside the handlers, never at module import.
"""

from __future__ import annotations

import argparse
import os
import signal
import sys
from typing import Sequence

from coopctrl.cli._core import (PROG, SUBCOMMANDS, Terminated, UsageError, _Parser, _one_line,  # noqa: F401 (API)
                                one_line, parse_sets, resolve_scenario, scenarios_dir, subcommand)
from coopctrl.errors import CoopctrlError, DivergenceError, InfeasibleLoad, interruption_in
from coopctrl.io.console import OutputWriteError, cause_of, flush_standard_output, refused, visible

# Each module registers its subcommand on import, in the order of ``--help``.
from coopctrl.cli import run as _run  # noqa: E402,F401
from coopctrl.cli import list_scenarios as _list  # noqa: E402,F401
from coopctrl.cli import check as _check  # noqa: E402,F401
from coopctrl.cli import show as _show  # noqa: E402,F401
from coopctrl.cli import view as _view  # noqa: E402,F401
from coopctrl.cli import tradeoff as _tradeoff  # noqa: E402,F401
from coopctrl.cli import sweep as _sweep  # noqa: E402,F401
from coopctrl.cli import fidelity as _fidelity  # noqa: E402,F401
from coopctrl.cli import stability as _stability  # noqa: E402,F401
from coopctrl.cli import export_mjcf as _export_mjcf  # noqa: E402,F401
from coopctrl.cli import compare_plants as _compare_plants  # noqa: E402,F401


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser with every registered subcommand, or with the subcommand ``command`` alone: all a
    command line that starts with it needs (:func:`_main`). Building every subcommand's options took 3.4 to
    4.4 ms, `run`'s alone 0.5 to 0.8 ms (docs/performance.md); parsing takes microseconds."""
    parser = _Parser(
        prog=PROG,
        description="Simulation and control of several robot arms carrying one object through elastic grasps.",
        epilog="Exit codes: 0 ok, 1 run diverged or QP failed or the task is impossible (pre-flight) or a run of a "
        "sweep failed or the system refused an output (a full disk, a closed standard output), 2 bad input, "
        "130 interrupted (SIGINT), 143 terminated (SIGTERM).",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name, configure in SUBCOMMANDS.items():
        if command is None or name == command:
            configure(sub)
    return parser


def _stopped(interrupt: KeyboardInterrupt, terminated: list[int]) -> int:
    """Remove the temporary files of writes in progress; one line; 130 (SIGINT) or 143 (SIGTERM)."""
    from coopctrl.io.atomic import remove_pending

    remove_pending()
    signum = interrupt.signum if isinstance(interrupt, Terminated) else (terminated[0] if terminated else None)
    if signum is not None:
        print(f"{PROG}: terminated (signal {signum})", file=sys.stderr)
        return 128 + signum
    print(f"{PROG}: interrupted", file=sys.stderr)
    return 130


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the exit code. SIGTERM is handled like Ctrl-C (clean-up, exit 143)
    while it runs, in the main thread."""
    return _main_with_signals(argv, program=False)


#: Signals the program ignores once its work is over (see :func:`_main_with_signals`).
_END_SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _ignore_end_signals() -> None:
    """Ignore SIGINT and SIGTERM (whichever thread the kernel would deliver them to): the work is over."""
    for sig in _END_SIGNALS:
        signal.signal(sig, signal.SIG_IGN)


def _main_with_signals(argv: Sequence[str] | None, program: bool) -> int:
    """:func:`_main` with SIGTERM raised as :class:`Terminated` in the main thread.

    ``program=False`` (a call from Python) restores the previous SIGTERM handler at the end. ``program=True``
    (the ``coopctrl`` process) instead ignores SIGINT and SIGTERM from then on: the work is over (outputs
    whole, or cleaned up), and a signal landing between the end of the work and the end of the process
    would otherwise meet the restored default handler (death by the signal instead of the exit code) or
    interrupt the interpreter's own shut-down.
    """
    terminated: list[int] = []

    def on_sigterm(signum, frame) -> None:
        terminated.append(signum)
        raise Terminated(signum)

    resend: list = []  # the timer that raises a swallowed signal again

    def on_unraisable(hook) -> None:
        """A signal's exception raised where Python cannot propagate it (a callback: a weak reference's, an
        import lock's) would be printed as "Exception ignored" with its traceback, and the work would go on:
        the signal is sent again 1 ms later instead (from a timer thread, after this hook has returned), and
        its handler raises it where it propagates. After a SIGTERM, a finalizer's error is its consequence
        (an object it interrupted half-built) and is not printed: the stop's one line stands."""
        if isinstance(hook.exc_value, KeyboardInterrupt):
            import threading

            sig = hook.exc_value.signum if isinstance(hook.exc_value, Terminated) else signal.SIGINT
            timer = threading.Timer(0.001, os.kill, (os.getpid(), sig))
            timer.daemon = True
            resend.append(timer)
            timer.start()
            return
        if terminated:  # SIGTERM stopped the work: an object whose construction it cut short (a compiler's
            return      # handle, freed with the interruption's frames) fails in its finalizer; the one line says why
        previous_hook(hook)

    try:
        previous = signal.signal(signal.SIGTERM, on_sigterm)
    except ValueError:  # not the main thread: signals stay as they are
        previous = None
    previous_hook = sys.unraisablehook
    if previous is not None:
        sys.unraisablehook = on_unraisable
    try:
        code = _main(argv)
        if code == 130 and terminated:  # a handler that caught the interruption itself (sweep)
            code = 128 + terminated[0]
        return code
    except KeyboardInterrupt as stop:  # SIGTERM after _main's own handling
        return _stopped(stop, terminated)
    finally:
        if program:
            _ignore_end_signals()
        elif previous is not None:
            signal.signal(signal.SIGTERM, previous)
        if previous is not None:
            for timer in resend:  # the work is over: nothing to stop
                timer.cancel()
            sys.unraisablehook = previous_hook


def _main(argv: Sequence[str] | None) -> int:
    try:
        argv = sys.argv[1:] if argv is None else list(argv)
        command = str(argv[0]) if argv and str(argv[0]) in SUBCOMMANDS else None  # else every subcommand: --help, errors
        args = build_parser(command).parse_args(argv)
        code = int(args.handler(args))
        flush_standard_output()  # here, not at the interpreter's exit: a refusal is then one line and exit 1
        return code
    except SystemExit as exit_:  # --help / --version
        try:
            flush_standard_output()
        except OutputWriteError as err:
            return _environment(err)
        return exit_.code if isinstance(exit_.code, int) else (0 if exit_.code is None else 2)
    except KeyboardInterrupt as stop:
        return _stopped(stop, terminated=[])
    except OutputWriteError as err:  # a full disk, a closed or full standard output: the system's, not a bug
        return _environment(err)
    except (DivergenceError, InfeasibleLoad) as err:
        print(f"{PROG}: failed: {_one_line(err)}", file=sys.stderr)
        return 1
    except CoopctrlError as err:
        print(f"{PROG}: error: {_one_line(err)}", file=sys.stderr)
        return 2
    except Exception as exc:  # noqa: BLE001 - the command line never shows a traceback
        stop = interruption_in(exc)
        if stop is not None:
            return _stopped(stop, terminated=[])
        if isinstance(exc, BrokenPipeError) or (isinstance(exc, ValueError) and _stdout_closed()):
            return _environment(refused(sys.stdout, exc, True))  # a print() to a reader that stopped, or closed
        return _unexpected(exc)


def _stdout_closed() -> bool:
    return sys.stdout is not None and getattr(sys.stdout, "closed", False)


def _environment(err: OSError) -> int:
    """One line for a refusal of the system (a full disk, a folder that cannot be written, a closed output
    stream) naming the place and the cause; exit 1. The message goes to stderr; if stderr refuses it too,
    the exit code alone says it."""
    if isinstance(err, OutputWriteError):
        text = str(err)
    else:
        place = err.filename if err.filename is not None else None
        text = cause_of(err) + ("" if place is None else f": {visible(os.fsdecode(place))}")
    try:
        print(f"{PROG}: failed: {text}", file=sys.stderr, flush=True)
    except (OSError, ValueError, AttributeError):
        pass
    return 1


def _unexpected(exc: Exception) -> int:
    """One line for an error that no check foresaw: numerical ones (overflow, a failed factorization,
    memory) are a failed run, exit 1; anything else is a bug to report, also exit 1 (the traceback is
    printed with ``COOPCTRL_TRACEBACK=1``)."""
    if os.environ.get("COOPCTRL_TRACEBACK"):
        import traceback

        traceback.print_exception(exc)
    if isinstance(exc, OSError) and exc.errno is not None:  # the system refused: a disk, a folder, a stream
        return _environment(exc)
    numerical = (OverflowError, FloatingPointError, ZeroDivisionError, MemoryError)
    name = type(exc).__name__
    if isinstance(exc, numerical) or name == "LinAlgError":
        print(f"{PROG}: failed: numerical failure ({name}: {_one_line(exc)}); the scene's values are probably "
              "out of any physical range (check the masses, stiffnesses, gains and steps)", file=sys.stderr)
    else:
        print(f"{PROG}: internal error (a bug, please report it with the command): {name}: {_one_line(exc)} "
              "(COOPCTRL_TRACEBACK=1 prints the traceback)", file=sys.stderr)
    return 1


def console_main() -> None:
    """The ``coopctrl`` program: :func:`main`, then exit with its code.

    After an interruption (130, 143) the process ends with ``os._exit`` once stdout and stderr are
    flushed: when Ctrl-C lands inside a library that runs code through ``PyRun_String`` (during an
    import), CPython marks the KeyboardInterrupt as unhandled even though :func:`main` handled it, and
    would then end the process by SIGINT (status -2) instead of the documented 130. Everything to clean
    up was cleaned before :func:`main` returned (temporary files, sweep workers)."""
    try:
        code = _main_with_signals(None, program=True)
    except KeyboardInterrupt as stop:  # landed as the work ended, before the signals were held
        _ignore_end_signals()
        code = 128 + stop.signum if isinstance(stop, Terminated) else 130
    if code in (130, 143):
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(code)
    sys.exit(code)


if __name__ == "__main__":
    console_main()
