"""The built-in scenes: the ``scenarios/*.toml`` files shipped with coopctrl, found by name.

In a checkout (and in the README's editable install) they are the files of ``scenarios/`` at the
repository root. An installed wheel carries the same files as the package data of
``coopctrl.scenarios`` (``pyproject.toml`` maps that package to the ``scenarios/`` folder), found
through :mod:`importlib.resources`. Either way :func:`builtin_dir` is the one folder they are read
from, so ``coopctrl list``, ``coopctrl run NAME`` and ``coopctrl.load_scenario(NAME)`` agree.

Pure Python (no numpy): the command line resolves names before anything heavy is imported.
"""

from __future__ import annotations

import os
from pathlib import Path

#: The package that carries the scenes in an installed wheel (``pyproject.toml``, ``package-dir``).
PACKAGE = "coopctrl.scenarios"

#: The ``coopctrl`` package's folder (found from this file: importing the package's API is not needed).
_PACKAGE_DIR = Path(__file__).resolve().parent.parent


def _checkout_dir() -> Path | None:
    """``scenarios/`` beside the imported ``coopctrl`` package when it runs from a checkout (the
    repository root has ``pyproject.toml``), else None."""
    root = _PACKAGE_DIR.parent
    folder = root / "scenarios"
    return folder if (root / "pyproject.toml").is_file() and folder.is_dir() else None


def builtin_dir() -> Path:
    """The folder of the built-in scenes: the checkout's ``scenarios/``, else the installed package
    data of :data:`PACKAGE`. A folder that does not exist is returned as is (``coopctrl list`` then
    says it is empty)."""
    folder = _checkout_dir()
    if folder is not None:
        return folder
    from importlib import resources

    try:
        files = resources.files(PACKAGE)
    except ModuleNotFoundError:  # neither a checkout nor an installed wheel: nothing shipped
        return _PACKAGE_DIR / "scenarios"
    return Path(os.fspath(files))  # a wheel installs unzipped: a real folder


def builtin_names() -> tuple[str, ...]:
    """Names (file stems) of the built-in scenes, sorted."""
    folder = builtin_dir()
    return tuple(sorted(p.stem for p in folder.glob("*.toml"))) if folder.is_dir() else ()


def builtin_path(name: str) -> Path | None:
    """The file of the built-in scene ``name`` (``"two_panda_carry"`` or ``"two_panda_carry.toml"``),
    or None when there is no such scene. Only a plain file name is looked up (no folder part)."""
    if not isinstance(name, str) or not name or "/" in name or os.sep in name or name in (".", ".."):
        return None
    folder = builtin_dir()
    for candidate in (folder / name, folder / f"{name}.toml"):
        if candidate.suffix == ".toml" and candidate.is_file():
            return candidate
    return None


def resolve(argument: str | os.PathLike) -> Path:
    """A path as given if it exists, else the built-in scene of that name, else the path as given
    (loading then reports it missing)."""
    path = Path(argument)
    if path.exists():
        return path
    found = builtin_path(os.fspath(argument))
    return found if found is not None else path
