"""Writing outputs where the system may refuse them: a full disk, a full or closed standard output, a
terminal that cannot show every character, a name that would drive the terminal.

:class:`OutputWriteError` names the place and the cause ("no space left on device writing
out/run1/result.npz"); the command line reports it as a failed run (exit 1). :func:`say` prints a line
that any standard output can take: characters its encoding lacks (a non-ASCII path on an ASCII
terminal, a lone surrogate) are printed escaped (``\\xe9``), never an error; a closed standard output
is an :class:`OutputWriteError` too. :func:`visible` is the one form in which the command line echoes a
path or a name (escape sequences, line breaks and bidirectional overrides shown as escapes).
"""

from __future__ import annotations

import errno
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

    def __init__(self, place: str, error: OSError, note: str = ""):
        super().__init__(error.errno, error.strerror)
        self.place = place
        self.note = note
        self.cause = cause_of(error)

    def __str__(self) -> str:
        return f"{self.cause} writing {visible(self.place)}" + (f" ({self.note})" if self.note else "")


def cause_of(error: OSError) -> str:
    """The system's reason for ``error`` in lower case, on one line: ``"no space left on device"``."""
    cause = " ".join(str(error.strerror or error or type(error).__name__).split())
    if len(cause) > 1 and cause[0].isupper() and cause[1].islower():
        cause = cause[0].lower() + cause[1:]  # "No space left" -> "no space left"
    return cause


#: Why standard output refused a write, for the errors whose system reason says little to a user.
_STDOUT_NOTES = {errno.EPIPE: "the program reading it stopped, e.g. `head`",
                 errno.EBADF: "it is closed"}


def visible(text) -> str:
    """``text`` (a path, a name, a message quoting them) as a terminal shows it, character for character.

    Every character that is not printable (``str.isprintable``: C0 and C1 controls such as ESC and BEL,
    DEL, line breaks, the bidirectional embeddings, overrides and isolates U+202A-U+202E and
    U+2066-U+2069, the marks U+200E, U+200F and U+061C, other invisible format characters, unassigned
    code points and lone surrogates) is written as its Python escape (``\\x1b``, ``\\u202e``,
    ``\\udcff``): printed, it cannot move the cursor, set the window title, end the line or reorder
    the text after it. Printable text, non-ASCII letters and spaces included, is returned unchanged.
    Every path or name the command line echoes goes through this function.
    """
    text = str(text)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def visible_lines(text) -> str:
    """A table or a text of several lines with each line through :func:`visible` (its line breaks kept)."""
    return "\n".join(visible(line) for line in str(text).split("\n"))


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
    stdout = stream is None or stream is sys.stdout
    stream = sys.stdout if stream is None else stream
    if stream is None:  # the interpreter found file descriptor 1 closed at start-up
        raise OutputWriteError("standard output", OSError(errno.EBADF, os.strerror(errno.EBADF)),
                               _STDOUT_NOTES[errno.EBADF])
    encoding = getattr(stream, "encoding", None) or "utf-8"
    line = str(text).encode(encoding, "backslashreplace").decode(encoding, "replace") + "\n"
    try:
        stream.write(line)
        stream.flush()
    except (OSError, ValueError) as exc:  # ValueError: a stream closed inside this process
        raise refused(stream, exc, stdout) from None


def flush_standard_output() -> None:
    """Flush standard output, as the interpreter would at exit, but with :class:`OutputWriteError` (naming
    it and the cause) instead of an "Exception ignored" message when the system refuses (a full disk, a
    reader that stopped)."""
    stream = sys.stdout
    if stream is None:
        return
    try:
        stream.flush()
    except (OSError, ValueError) as exc:
        raise refused(stream, exc, True) from None


def refused(stream: TextIO, exc: BaseException, stdout: bool) -> OutputWriteError:
    """The :class:`OutputWriteError` of a write to ``stream`` that failed with ``exc``; what is still
    buffered for the stream is dropped (:func:`_silence`), so that nothing fails a second time at exit."""
    _silence(stream)
    if not isinstance(exc, OSError):
        exc = OSError(errno.EBADF, os.strerror(errno.EBADF))
    place = "standard output" if stdout else str(getattr(stream, "name", "a stream"))
    return OutputWriteError(place, exc, _STDOUT_NOTES.get(exc.errno, "") if stdout else "")


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
