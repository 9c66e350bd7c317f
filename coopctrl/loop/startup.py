"""Start-up of a run: the kind of compiled kernels it needs, and whether the kernel cache holds them.

A run's machine code depends on its *kind*: the space (``"planar"``, ``"spatial"``) and the integrator
family (``"explicit"``: euler, symplectic_euler, rk4 and the integrators stepped outside the kernel;
``"implicit"``: implicit_midpoint, implicit_euler, Newton in the kernel; ``"embedded"``: the
error-controlled pairs rk23 and rk45; ``"trbdf2"``: the error-controlled L-stable scheme). Every scene of a kind runs
the same compiled functions (a passive run's energy and the elastic split add small stages of their
own, compiled at their first use and not announced); the first run of a kind on a machine compiles
them (tens of seconds), later runs load them from the cache directory (:func:`plants.numba_cache.configure`, keyed on the
kernel sources), in a fraction of a second.

*Cold* or warm is read from the files of the cache directory, never from numba's internals:
numba writes one index file (``*.nbi``, named after the module and the function) per cached
function there. The end of a kind's start-up (:func:`started`, called by the run once its kernels are
compiled or loaded) writes a *stamp* ``<cache>/coopctrl-kinds/<kind>-<tree>.txt`` listing the index
files the cache then holds; a kind is cold (:func:`is_cold`) when it has no stamp, or when an index
file its stamp lists is gone. A stamp is per kind because kinds share functions (one index file holds
every compiled variant of its function: its presence alone does not say that this kind's variant is
in it), and per source tree (``<tree>``: a digest of its path), because numba's cache files are
per source path.
"""

from __future__ import annotations

import hashlib
import os
import threading
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Iterator

#: Spaces and integrator families of :class:`KernelKind`.
SPACES = ("planar", "spatial")
FAMILIES = ("explicit", "implicit", "embedded", "trbdf2")

#: Folder of the stamps, inside the cache directory.
STAMP_FOLDER = "coopctrl-kinds"

_listeners: list[Callable[["KernelKind", float], None]] = []
_lock = threading.Lock()
#: (kind, cache directory) already recorded warm by this process (a run checks its stamp once per process).
_recorded: set[tuple["KernelKind", str]] = set()


@dataclass(frozen=True)
class KernelKind:
    """The compiled kernels a run needs.

    Attributes:
        space: ``"planar"`` or ``"spatial"``.
        family: ``"explicit"``, ``"implicit"``, ``"embedded"`` or ``"trbdf2"`` (the integrator's family;
            see the module's docstring).
    """

    space: str
    family: str

    def __post_init__(self) -> None:
        if self.space not in SPACES:
            raise ValueError(f"KernelKind: space = {self.space!r} is invalid: expected one of {SPACES}")
        if self.family not in FAMILIES:
            raise ValueError(f"KernelKind: family = {self.family!r} is invalid: expected one of {FAMILIES}")

    @property
    def name(self) -> str:
        """``"<space>-<family>"`` (``"planar-explicit"``): the stamp's name."""
        return f"{self.space}-{self.family}"


def family_of(integrator: str) -> str:
    """``"implicit"`` for an integrator the kernel steps by Newton iterations (implicit_midpoint,
    implicit_euler), ``"embedded"`` for rk23 and rk45, ``"trbdf2"`` for trbdf2, else ``"explicit"``
    (an integrator the kernel lacks steps in Python and runs the explicit kernels)."""
    if not isinstance(integrator, str):
        raise TypeError(f"integrator = {integrator!r} is invalid: expected an integrator name (str)")
    from coopctrl.integrators import methods  # the codes alone: this check does not import the compiler

    method = methods.METHODS.get(integrator)
    if method == methods.METHOD_ADAPTIVE:
        return "trbdf2" if integrator == "trbdf2" else "embedded"
    return "implicit" if method == methods.METHOD_SDIRK else "explicit"


def kind_of(scenario) -> KernelKind:
    """The :class:`KernelKind` a :class:`~coopctrl.scenario.Scenario`'s run needs."""
    return KernelKind(scenario.scene.space, family_of(scenario.simulation.integrator))


def kind_of_run(spatial: bool, family: str) -> KernelKind:
    """The :class:`KernelKind` of a run from what the loop decided: ``spatial`` and its integration
    plan's family (:data:`FAMILIES`)."""
    return KernelKind("spatial" if spatial else "planar", family)


def cache_directory() -> Path:
    """The kernel cache directory of this source tree (:func:`plants.numba_cache.configure`)."""
    from plants import numba_cache

    return Path(numba_cache.configure())


def _tree() -> str:
    """A digest of this source tree's path (the compiler's cache files are per source path)."""
    return hashlib.sha256(str(Path(__file__).resolve().parent.parent.parent).encode()).hexdigest()[:12]


def stamp_path(kind: KernelKind, directory: Path | None = None) -> Path:
    """The stamp of ``kind`` in the cache ``directory`` (default: :func:`cache_directory`)."""
    directory = cache_directory() if directory is None else Path(directory)
    return directory / STAMP_FOLDER / f"{kind.name}-{_tree()}.txt"


def index_files(directory: Path) -> list[str]:
    """The index files (``*.nbi``) under the cache ``directory``, as sorted paths relative to it."""
    directory = Path(directory)
    try:
        return sorted(p.relative_to(directory).as_posix() for p in directory.rglob("*.nbi"))
    except OSError:
        return []


def is_cold(kind: KernelKind, directory: Path | None = None) -> bool:
    """True when a run of ``kind`` will compile its kernels: no stamp of ``kind`` in the cache
    ``directory`` (default: :func:`cache_directory`), or an index file its stamp lists is missing."""
    directory = cache_directory() if directory is None else Path(directory)
    try:
        listed = [line for line in stamp_path(kind, directory).read_text(encoding="utf-8").splitlines() if line]
    except (OSError, UnicodeDecodeError):
        return True
    root = os.fspath(directory)  # plain strings: a Path per listed file costs more than its stat
    return not listed or not all(os.path.isfile(os.path.join(root, name)) for name in listed)


def compiles_here(kind: KernelKind) -> bool:
    """Whether a run of ``kind`` in this process may compile its kernels: :func:`is_cold` in this tree's
    cache, unless this process has already recorded ``kind`` warm there (:func:`record_warm`), which a
    sweep's later runs then do not read from the disk again (about 1 ms a run)."""
    directory = cache_directory()
    return (kind, str(directory)) not in _recorded and is_cold(kind, directory)


def record_warm(kind: KernelKind, directory: Path | None = None) -> None:
    """Write the stamp of ``kind`` (the index files the cache ``directory`` holds now) unless it is
    there: called once the kind's kernels are compiled or loaded. A cache that cannot be written keeps
    no stamp (the next run says again that it compiles, which it then does)."""
    directory = cache_directory() if directory is None else Path(directory)
    if (kind, str(directory)) in _recorded:  # once per process: a sweep's runs pay nothing for it
        return
    path = stamp_path(kind, directory)
    if not is_cold(kind, directory):
        _recorded.add((kind, str(directory)))
        return
    names = index_files(directory)
    if not names:  # nothing cached (an unwritable cache: the kernels were compiled in memory)
        return
    from coopctrl.io.atomic import write_text_if_possible

    if write_text_if_possible(path, "\n".join(names) + "\n"):
        _recorded.add((kind, str(directory)))


def started(kind: KernelKind, startup_s: float, directory: Path | None = None) -> None:
    """The run of ``kind`` has compiled or loaded its kernels in ``startup_s`` [s]: record the kind
    warm in the cache ``directory`` (:func:`record_warm`) and tell the listeners (:func:`listening`)."""
    record_warm(kind, directory)
    with _lock:
        listeners = list(_listeners)
    for listener in listeners:
        listener(kind, startup_s)


@contextmanager
def listening(listener: Callable[[KernelKind, float], None]) -> Iterator[None]:
    """Call ``listener(kind, startup_s)`` at the end of each run's start-up while inside (the command
    line stops its compile ticker there, before the first tick)."""
    with _lock:
        _listeners.append(listener)
    try:
        yield
    finally:
        with _lock:
            _listeners.remove(listener)

