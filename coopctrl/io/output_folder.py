"""The check of an output folder before any work: a folder that is replaced as a whole
(:mod:`coopctrl.io.atomic_dir`) may only hold what an earlier run of the same command wrote there."""

from __future__ import annotations

import fnmatch
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class FolderKind:
    """What a command writes into its output folder.

    Attributes:
        command: The command, for messages (``"coopctrl run --out"``).
        files: Names (or ``fnmatch`` patterns) of the regular files it writes.
        folders: Names of the sub-folders it writes.
    """

    command: str
    files: tuple[str, ...]
    folders: tuple[str, ...] = ()

    def expects_file(self, name: str) -> bool:
        return any(fnmatch.fnmatchcase(name, pattern) for pattern in self.files)


#: ``coopctrl run --out``: the result, its plots and replay, the scenario and its robot files.
RESULT_FOLDER = FolderKind("coopctrl run --out", ("result.npz", "result.csv", "summary.json", "scenario.toml",
                                                  "replay.html", "*.png"), ("robots",))
#: ``coopctrl sweep --out``: the rows.
SWEEP_FOLDER = FolderKind("coopctrl sweep --out", ("sweep.csv", "sweep.json"))


def check_output_folder(path: str | os.PathLike, kind: FolderKind) -> Path:
    """Refuse a place where the folder of ``kind`` cannot be written as one unit; returns the path.

    Accepted: a missing folder whose parent can be created and written, an empty folder, or a folder
    holding only what ``kind`` writes (an earlier result, replaced as a whole). Refused, each with the
    reason: a folder holding anything else (it would be lost), an entry of the right name and the wrong
    type (``result.npz`` a directory), the current directory or one above it, a mount point, and a parent
    folder where the sibling temporary folder cannot be made.

    Raises:
        ValueError: ``"'PATH' is invalid: ...; expected ..."`` (one line).
    """
    text = os.fspath(path)
    path = Path(text).expanduser()
    allowed = f"a new folder, an empty one, or the folder of an earlier `{kind.command}`"
    real = Path(os.path.realpath(path))
    if path.exists():
        if not path.is_dir():
            raise ValueError(f"{text!r} is invalid: it exists and is not a directory; expected {allowed}")
        cwd = Path(os.path.realpath(os.getcwd()))
        if real == cwd or real in cwd.parents:
            raise ValueError(f"{text!r} is invalid: it is the current directory or holds it, and the output folder is "
                             "replaced as a whole; expected a sub-folder such as 'out/run1'")
        if os.path.ismount(real):
            raise ValueError(f"{text!r} is invalid: it is a mount point, and the output folder is replaced as a whole; "
                             "expected a folder inside it")
        foreign, wrong = [], []
        for entry in sorted(os.scandir(path), key=lambda e: e.name):
            if kind.expects_file(entry.name):
                if not entry.is_file(follow_symlinks=False):
                    wrong.append(f"{entry.name!r} is not a regular file")
            elif entry.name in kind.folders:
                if not entry.is_dir(follow_symlinks=False):
                    wrong.append(f"{entry.name!r} is not a directory")
            else:
                foreign.append(entry.name)
        if wrong:
            raise ValueError(f"{text!r} is invalid: {wrong[0]}, and `{kind.command}` writes it as one; "
                             f"expected {allowed} (remove or rename the entry)")
        if foreign:
            shown = ", ".join(repr(n) for n in foreign[:3]) + (f" and {len(foreign) - 3} more" if len(foreign) > 3 else "")
            raise ValueError(f"{text!r} is invalid: it holds {shown}, which `{kind.command}` does not write and would "
                             f"lose when it replaces the folder; expected {allowed}")
    check_writable(text, real.parent, allowed, where=f"beside it in {str(real.parent)!r}")
    return path


def check_writable(text: str, directory: Path, allowed: str, where: str = "there") -> None:
    """Refuse (ValueError, naming ``text``) a ``directory`` that cannot be made or written: make its
    missing parents and a probe folder in it, then remove what was made, so the check leaves nothing
    behind and says exactly what the system refused. ``where`` words the place in the message."""
    created: list[Path] = []
    try:
        missing = []
        up = directory
        while not up.exists():
            missing.append(up)
            if up.parent == up:
                break
            up = up.parent
        if up.exists() and not up.is_dir():
            raise ValueError(f"{text!r} is invalid: {str(up)!r} is not a directory; expected {allowed}")
        for folder in reversed(missing):
            folder.mkdir()
            created.append(folder)
        probe = tempfile.mkdtemp(dir=directory, prefix=".coopctrl-probe.", suffix=".tmp")
        shutil.rmtree(probe, ignore_errors=True)
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise ValueError(f"{text!r} is invalid: cannot write {where} ({reason}); expected {allowed}") from None
    finally:
        for folder in reversed(created):
            try:
                folder.rmdir()
            except OSError:
                pass
