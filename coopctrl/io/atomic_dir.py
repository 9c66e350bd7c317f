"""Atomic directory writing: a folder of outputs is built in a sibling temporary folder, then put in
place of the target in one step, so that a reader sees the old folder or the new one, never a mix.

On Linux the two folders are exchanged by ``renameat2(RENAME_EXCHANGE)`` (one atomic step); elsewhere,
or where the file system refuses the exchange, the old folder is renamed aside, the new one renamed in,
and the old one removed (a reader may then find no folder for an instant, never a mixed one).
"""

from __future__ import annotations

import ctypes
import errno
import os
import shutil
import signal
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from coopctrl.io.atomic import _HELD, _PENDING, _fsync_directory, _permissions

#: ``renameat2`` flag: exchange the two paths atomically (Linux >= 3.15).
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _temporary_prefix(target: Path) -> str:
    return f".{target.name}.coopctrl-"


def exchange_directories(a: str, b: str) -> bool:
    """Swap the directories ``a`` and ``b`` in one step; False when the system cannot."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    renameat2.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    if renameat2(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    code = ctypes.get_errno()
    if code in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP, errno.EOPNOTSUPP):
        return False
    raise OSError(code, os.strerror(code), b)


def _held():
    """Block SIGINT and SIGTERM (restored by the caller with the returned mask); None off POSIX."""
    mask = getattr(signal, "pthread_sigmask", None)
    return (mask, mask(signal.SIG_BLOCK, _HELD)) if mask else None


def _release(held) -> None:
    if held:
        held[0](signal.SIG_SETMASK, held[1])


def remove_stale(target: Path) -> list[str]:
    """Remove the temporary folders that a process killed outright (SIGKILL, a power cut) left beside
    ``target``: their names carry the writer's process id, and that process no longer exists."""
    removed = []
    parent = target.parent
    prefix = _temporary_prefix(target)
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    for entry in entries:
        if not (entry.name.startswith(prefix) and entry.name.endswith(".tmp")):
            continue
        pid_text = entry.name[len(prefix):].split("-", 1)[0]
        if not pid_text.isdigit() or int(pid_text) == os.getpid():
            continue
        try:
            os.kill(int(pid_text), 0)
            continue  # its writer is still at work
        except ProcessLookupError:
            pass
        except PermissionError:
            continue
        shutil.rmtree(entry.path, ignore_errors=True)
        removed.append(entry.path)
    return removed


@contextmanager
def atomic_directory(target: str | os.PathLike) -> Iterator[Path]:
    """Yield an empty temporary folder beside ``target``; when the block ends without an exception, put
    it in place of ``target`` in one step (the old folder, if any, is removed afterwards). On any
    exception (``KeyboardInterrupt`` included) the temporary folder is removed and ``target`` is left as
    it was. A symbolic link ``target`` keeps pointing where it did: the folder it names is replaced.

    Args:
        target: The output folder. Its parent is created if missing; it must not be a mount point (a
            folder cannot be renamed across file systems; ``--out`` checks this first).

    Example:
        >>> with atomic_directory("out/run1") as folder:  # doctest: +SKIP
        ...     (folder / "summary.json").write_text("{}")
    """
    target = Path(os.path.realpath(os.fspath(target)))
    target.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(target)
    held = _held()
    try:
        folder = tempfile.mkdtemp(dir=target.parent, prefix=f"{_temporary_prefix(target)}{os.getpid()}-", suffix=".tmp")
        _PENDING.add(folder)
    finally:
        _release(held)
    try:
        os.chmod(folder, _permissions(target, new=0o777))
        yield Path(folder)
        _fsync_directory(Path(folder))
        _put_in_place(folder, target)
    except BaseException:
        held = _held()  # a second Ctrl-C cannot interrupt the clean-up
        try:
            shutil.rmtree(folder, ignore_errors=True)
            _PENDING.discard(folder)
        finally:
            _release(held)
        raise
    _fsync_directory(target.parent)


def _put_in_place(folder: str, target: Path) -> None:
    """Rename ``folder`` onto ``target``; an existing ``target`` is exchanged with it, then removed."""
    held = _held()
    try:
        try:
            os.rename(folder, target)  # no target yet (or an empty one: rename replaces an empty folder)
            _PENDING.discard(folder)
            return
        except OSError as exc:
            if exc.errno not in (errno.EEXIST, errno.ENOTEMPTY):
                raise
        if exchange_directories(folder, str(target)):  # ``folder`` now holds the old result
            shutil.rmtree(folder, ignore_errors=True)
            _PENDING.discard(folder)
            return
        old = tempfile.mkdtemp(dir=target.parent, prefix=f"{_temporary_prefix(target)}{os.getpid()}-old-", suffix=".tmp")
        _PENDING.add(old)
        os.rename(target, old)  # replaces the empty ``old``
        try:
            os.rename(folder, target)
        except BaseException:
            os.rename(old, target)
            raise
        _PENDING.discard(folder)
        shutil.rmtree(old, ignore_errors=True)
        _PENDING.discard(old)
    finally:
        _release(held)
