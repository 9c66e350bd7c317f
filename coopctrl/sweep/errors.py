"""Errors of a sweep: a bad ``--grid``, a missing optional extra, an unreachable Dask scheduler, and
the interruption that carries the rows finished so far.

The first three are :class:`~coopctrl.errors.CoopctrlError` subclasses (bad input: the command line
prints one line and exits 2). :class:`SweepInterrupted` is a :class:`KeyboardInterrupt`, so code that
does not handle it still stops as on Ctrl-C.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from coopctrl.errors import CoopctrlError

if TYPE_CHECKING:
    from coopctrl.sweep.results import SweepResult


class SweepError(CoopctrlError):
    """Base class of the sweep's input and set-up errors."""


class GridError(SweepError, ValueError):
    """A ``--grid PATH=V1,V2,...`` argument is malformed.

    Attributes:
        argument: The argument as given.
        allowed: What would have been accepted.
    """

    def __init__(self, argument: str, allowed: str):
        self.argument = argument
        self.allowed = allowed
        super().__init__(f"--grid {argument!r} is invalid: expected {allowed}")


class MissingExtra(SweepError, ImportError):
    """An optional dependency is not installed; the message names the extra that provides it."""

    def __init__(self, feature: str, module: str, extra: str):
        self.feature = feature
        self.module = module
        self.extra = extra
        super().__init__(f"{feature} needs the package '{module}', which is not installed; pip install 'coopctrl[{extra}]'")


class SchedulerError(SweepError, ConnectionError):
    """The Dask scheduler at ``address`` cannot be reached.

    Attributes:
        address: The scheduler address as given (``tcp://host:8786``).
        detail: The underlying error, on one line.
    """

    def __init__(self, address: str, detail: str):
        self.address = address
        self.detail = detail
        super().__init__(
            f"--scheduler {address!r}: cannot connect to a Dask scheduler ({detail}); "
            "start one (`dask scheduler`, then `dask worker ADDRESS`) or check the address, e.g. tcp://127.0.0.1:8786"
        )


class SweepInterrupted(KeyboardInterrupt):
    """The sweep was interrupted (Ctrl-C); ``result`` holds the runs finished before it, already saved
    when the sweep had an output directory.

    Attributes:
        result: The partial :class:`~coopctrl.sweep.results.SweepResult` (``result.complete`` is False).
    """

    def __init__(self, result: "SweepResult"):
        self.result = result
        super().__init__(f"sweep interrupted after {len(result.rows)} of {result.runs} runs")
