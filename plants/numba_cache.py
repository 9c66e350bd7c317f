"""numba's on-disk cache, keyed on every kernel source.

numba keys a cached compiled function on its own source file only: when a function it calls
(a *callee*, inlined into the caller's machine code) changes in another file, the caller's cache
still matches and stale machine code runs. So the cache lives in a directory named by a digest of
every source file of ``plants`` and ``coopctrl`` that numba compiles (the files that import
numba), of the numba, llvmlite and Python versions: any change of a kernel source gives a new,
empty directory, and the next run compiles afresh.

The directory is ``$NUMBA_CACHE_DIR/coopctrl-<digest>`` when ``NUMBA_CACHE_DIR`` is set, else
``$XDG_CACHE_HOME/coopctrl/numba/coopctrl-<digest>`` (``~/.cache`` by default; the system's temporary
folder if that cannot be written). Directories of other digests unused for :data:`PRUNE_AFTER_S` are
removed. :func:`configure` must run before any
``@njit(cache=True)`` decorator does; ``plants/__init__.py`` and ``coopctrl/__init__.py`` call it
first thing.
"""

from __future__ import annotations

import hashlib
import os
import shutil
import sys
import time
from pathlib import Path

#: Cache directories of other digests unused this long are removed [s] (one week).
PRUNE_AFTER_S = 7 * 24 * 3600.0

_ROOTS = ("plants", "coopctrl")
_configured: str | None = None


def kernel_sources(top: Path) -> list[Path]:
    """The ``.py`` files under ``top``'s ``plants`` and ``coopctrl`` packages that import numba."""
    out = []
    for root in _ROOTS:
        for path in sorted((top / root).rglob("*.py")):
            try:
                text = path.read_text(encoding="utf-8", errors="replace")
            except OSError:
                continue
            if "numba" in text:
                out.append(path)
    return out


def cache_key(top: Path) -> str:
    """A digest of the kernel sources under ``top`` and of the compiler versions (16 hex digits).
    numba itself is not imported (``import plants`` stays cheap)."""
    from importlib.metadata import PackageNotFoundError, version

    def v(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "-"

    h = hashlib.sha256(f"{v('numba')} {v('llvmlite')} {sys.version}".encode())
    for path in kernel_sources(top):
        h.update(str(path.relative_to(top)).encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


def cache_base() -> Path:
    """Where the keyed directories live: ``$NUMBA_CACHE_DIR`` or the user's cache folder."""
    given = os.environ.get("NUMBA_CACHE_DIR")
    if given:
        return Path(given)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "coopctrl" / "numba"


def keyed_directory(top: Path | None = None) -> Path:
    """The cache directory of the source tree ``top`` (this package's tree by default):
    ``cache_base() / "coopctrl-<digest>"``, or ``cache_base()`` itself when it already is that directory
    (a child process inherits the ``NUMBA_CACHE_DIR`` that :func:`configure` set). Creates nothing."""
    top = Path(__file__).resolve().parent.parent if top is None else Path(top)
    base = cache_base()
    name = f"coopctrl-{cache_key(top)}"
    return base if base.name == name else base / name


def configure(top: Path | None = None) -> str:
    """Point numba's cache at the directory of this source tree's digest; return that directory.
    Idempotent: the first call in a process decides."""
    global _configured
    if _configured is not None:
        return _configured
    base = cache_base()
    directory = keyed_directory(top)
    name = directory.name
    try:
        directory.mkdir(parents=True, exist_ok=True)
        os.utime(directory)
        _prune(base, keep=directory.name)
    except OSError:  # an unwritable home: the system's temporary folder (a cache costs only compile time)
        import tempfile

        directory = Path(tempfile.gettempdir()) / f"coopctrl-numba-{os.getuid() if hasattr(os, 'getuid') else 0}" / name
        try:
            directory.mkdir(parents=True, exist_ok=True)
        except OSError:
            pass  # numba then warns that it cannot cache, and compiles in memory
    os.environ["NUMBA_CACHE_DIR"] = str(directory)  # read by numba when it is imported (and by child processes)
    if "numba" in sys.modules:  # already imported: its config is read at each cached function's definition
        sys.modules["numba"].config.CACHE_DIR = str(directory)
    _configured = str(directory)
    return _configured


def _prune(base: Path, keep: str) -> None:
    now = time.time()
    if base.name.startswith("coopctrl-"):
        return
    for entry in base.glob("coopctrl-*"):
        try:
            if entry.name != keep and entry.is_dir() and now - entry.stat().st_mtime > PRUNE_AFTER_S:
                shutil.rmtree(entry, ignore_errors=True)
        except OSError:
            continue
