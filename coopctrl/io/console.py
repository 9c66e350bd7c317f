"""Writing outputs where the system may refuse them: a full disk, a full or closed standard output, a
terminal that cannot show every character.

:class:`OutputWriteError` names the place and the cause ("no space left on device writing
out/run1/result.npz"); the command line reports it as a failed run (exit 1). :func:`say` prints a line
that any standard output can take: characters its encoding lacks (a non-ASCII path on an ASCII
terminal, a lone surrogate) are printed escaped (``\\xe9``), never an error.
"""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager
from typing import Iterator, TextIO


class OutputWriteError(OSError):
    """Writing ``place`` failed for a reason of the system (an ``OSError``); the run itself was fine.

    Attributes:
        place: The file, folder or stream being written (``"standard output"``).
        cause: The system's reason, e.g. ``"no space left on device"``.
        errno: The system's error number (``errno.ENOSPC``), or ``None``.
    """

    def __init__(self, place: str, error: OSError):
        super().__init__(error.errno, error.strerror)
        self.place = place
        cause = " ".join(str(error.strerror or error or type(error).__name__).split())
        if len(cause) > 1 and cause[0].isupper() and cause[1].islower():
            cause = cause[0].lower() + cause[1:]  # "No space left" -> "no space left"
        self.cause = cause

    def __str__(self) -> str:
        return f"{self.cause} writing {escaped(self.place)}"


def escaped(text: str, encoding: str = "ascii") -> str:
    """``text`` with every character that ``encoding`` cannot write (and lone surrogates) as a
    backslash escape, so that printing it cannot fail."""
    return str(text).encode(encoding, "backslashreplace").decode(encoding)


@contextmanager
def writing(place: str) -> Iterator[None]:
    """Turn an ``OSError`` of the block into :class:`OutputWriteError` naming ``place``."""
    try:
        yield
    except OutputWriteError:
        raise
    except OSError as exc:
        raise OutputWriteError(str(place), exc) from None


def say(text: str = "", stream: TextIO | None = None) -> None:
    """Print ``text`` and a newline on ``stream`` (default standard output) and flush it.

    Characters the stream's encoding lacks are escaped. If the stream refuses the write (``/dev/full``,
    a closed pipe's other errors), its file descriptor is pointed at ``/dev/null`` so that the
    interpreter's own flush at exit does not fail a second time, and :class:`OutputWriteError` is raised.
    """
    stream = sys.stdout if stream is None else stream
    encoding = getattr(stream, "encoding", None) or "utf-8"
    line = str(text).encode(encoding, "backslashreplace").decode(encoding, "replace") + "\n"
    try:
        stream.write(line)
        stream.flush()
    except BrokenPipeError:
        _silence(stream)
        raise
    except OSError as exc:
        _silence(stream)
        raise OutputWriteError("standard output" if stream is sys.stdout else getattr(stream, "name", "a stream"),
                               exc) from None


def _silence(stream: TextIO) -> None:
    """Send what is still buffered for ``stream`` to ``/dev/null``."""
    try:
        fd = stream.fileno()
    except (OSError, ValueError, AttributeError):
        return
    try:
        null = os.open(os.devnull, os.O_WRONLY)
    except OSError:
        return
    try:
        os.dup2(null, fd)
    finally:
        os.close(null)
