"""Atomic file writing: after a crash or Ctrl-C a file is either whole or absent (or unchanged)."""

from __future__ import annotations

import os
import signal
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Iterator


#: The temporary files (and folders, :mod:`coopctrl.io.atomic_dir`) being written, removed by
#: :func:`remove_pending` when the process is stopped by a signal in a place where their own clean-up
#: cannot run.
_PENDING: set[str] = set()
#: Signals held back between creating a temporary file and registering it (a few microseconds).
_HELD = {signal.SIGINT, signal.SIGTERM}


def remove_pending() -> list[str]:
    """Remove the temporary files and folders of writes still in progress (the command line calls it on
    SIGINT and SIGTERM); returns their names. Targets are untouched: they stay as they were before the
    write."""
    import shutil

    removed = []
    for name in list(_PENDING):
        try:
            if os.path.isdir(name) and not os.path.islink(name):
                shutil.rmtree(name)
            else:
                os.unlink(name)
            removed.append(name)
        except FileNotFoundError:
            pass
        except OSError:
            shutil.rmtree(name, ignore_errors=True)
        _PENDING.discard(name)
    return removed


@contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "w", *, encoding: str | None = None) -> Iterator[IO]:
    """Open a temporary file next to ``path`` for writing; on success flush, fsync and
    ``os.replace`` it onto ``path``. On any exception (``KeyboardInterrupt`` included) the
    temporary file is removed and ``path`` is left as it was.

    Args:
        path: Target file. Its directory must exist.
        mode: ``"w"`` (text, UTF-8 unless ``encoding``) or ``"wb"`` (binary).
        encoding: Text encoding for ``"w"``.

    Example:
        >>> with atomic_write(directory / "summary.json") as f:  # doctest: +SKIP
        ...     json.dump(summary, f)
    """
    if mode not in ("w", "wb"):
        raise ValueError(f"atomic_write: mode = {mode!r} is invalid: expected 'w' or 'wb'")
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    mask = getattr(signal, "pthread_sigmask", None)  # POSIX only
    held = mask(signal.SIG_BLOCK, _HELD) if mask else None  # no signal between mkstemp and registering
    try:
        fd, tmp_name = tempfile.mkstemp(dir=directory, prefix=f".{target.name}.", suffix=".tmp")
        _PENDING.add(tmp_name)
    finally:
        if mask:
            mask(signal.SIG_SETMASK, held)
    try:
        os.fchmod(fd, _permissions(target))
        if mode == "wb":
            handle = os.fdopen(fd, "wb")
        else:
            handle = os.fdopen(fd, "w", encoding=encoding or "utf-8", newline="")
        with handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp_name, target)
    except BaseException:
        try:
            os.unlink(tmp_name)
        except FileNotFoundError:
            pass
        raise
    finally:
        _PENDING.discard(tmp_name)
    _fsync_directory(directory)


def _permissions(target: Path, new: int = 0o666) -> int:
    """Keep an existing file's (or folder's) permissions; a new one gets ``new`` (0666 for a file,
    0777 for a folder) minus the umask (``mkstemp`` / ``mkdtemp`` would leave 0600 / 0700)."""
    try:
        return target.stat().st_mode & 0o777
    except OSError:
        umask = os.umask(0)
        os.umask(umask)
        return new & ~umask


def _fsync_directory(directory: Path) -> None:
    """Make the rename durable (best effort: not every platform can open a directory)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)
