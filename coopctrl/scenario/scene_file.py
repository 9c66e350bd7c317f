"""Reading a scene file: a regular file of at most :data:`MAX_SCENE_BYTES`, UTF-8, TOML.

A scene is a few kilobytes (the largest shipped one is 3 kB). The reader refuses, before reading
anything, what is not a regular file (a directory, a FIFO that would block, a device such as
``/dev/zero`` or ``/dev/urandom`` that never ends), and reads at most ``MAX_SCENE_BYTES + 1`` bytes
so that an endless or huge file costs at most that much memory and time. TOML nested deeper than
the parser's recursion allows, or than :data:`coopctrl.scenario.text.MAX_DEPTH`, is refused in one
line. Every failure is a :class:`~coopctrl.errors.ScenarioError` naming the file.

Pure Python (no numpy): loading a scenario must stay cheap.
"""

from __future__ import annotations

import os
import stat
import tomllib
from pathlib import Path
from typing import Any

from coopctrl.errors import ScenarioError
from coopctrl.scenario.text import MAX_DEPTH, check_tree, printable

#: Largest scene file read, in bytes (1 MiB: several hundred times the largest shipped scene).
MAX_SCENE_BYTES = 1 << 20


def file_error(source: str, message: str) -> ScenarioError:
    """A file-level ScenarioError (path ``""``) whose message is ``"<source>: <message>"``."""
    shown = printable(source)
    err = ScenarioError("", source, message, source=shown)
    err.args = (f"{shown}: {message}",)
    return err


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
                       (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def read_scene_text(path: str | os.PathLike) -> str:
    """The text of the scene file ``path``.

    Raises:
        ScenarioError: the file is missing, not a regular file, larger than :data:`MAX_SCENE_BYTES`,
            unreadable or not UTF-8.
    """
    source = os.fspath(path)
    fix = "give the path of a scenario .toml file (see `coopctrl list`)"
    try:
        info = os.stat(source)
    except FileNotFoundError:
        raise file_error(source, f"file not found; {fix}") from None
    except (OSError, ValueError) as err:  # ValueError: a NUL byte or text the file system cannot encode
        reason = err.strerror if isinstance(err, OSError) and err.strerror else str(err)
        raise file_error(source, f"cannot read the file ({reason}); {fix}") from None
    if not stat.S_ISREG(info.st_mode):
        raise file_error(source, f"{_kind(info.st_mode)}, not a regular file; {fix}")
    if info.st_size > MAX_SCENE_BYTES:
        raise file_error(source, f"{info.st_size} bytes; a scene file has at most {MAX_SCENE_BYTES} bytes (1 MiB)")
    try:
        # O_NONBLOCK: a file replaced by a FIFO after the check above cannot block the open
        fd = os.open(source, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
        with os.fdopen(fd, "rb") as handle:
            if not stat.S_ISREG(os.fstat(handle.fileno()).st_mode):
                raise file_error(source, f"not a regular file; {fix}")
            data = handle.read(MAX_SCENE_BYTES + 1)
    except OSError as err:
        raise file_error(source, f"cannot read the file ({err.strerror or type(err).__name__}); {fix}") from None
    if len(data) > MAX_SCENE_BYTES:
        raise file_error(source, f"more than {MAX_SCENE_BYTES} bytes; a scene file has at most {MAX_SCENE_BYTES} bytes (1 MiB)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise file_error(source, f"cannot read the file (not UTF-8: byte {err.start + 1} is {data[err.start]:#04x}); "
                         "give a UTF-8 .toml file") from None


def parse_scene_text(text: str, source: str) -> dict[str, Any]:
    """The TOML table of a scene's text, with every key and string checked (:func:`check_tree`).

    Raises:
        ScenarioError: a TOML syntax error, nesting too deep, or a refused string (naming its key).
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        msg = printable(" ".join(str(err).split()))
        raise file_error(source, f"TOML syntax error: {msg}; fix the syntax (https://toml.io)") from None
    except RecursionError:
        raise file_error(source, "tables or arrays nested too deeply for the TOML parser; a scene nests "
                         f"at most {MAX_DEPTH} levels") from None
    try:
        check_tree(data)
    except ScenarioError as err:
        raise ScenarioError(err.path, err.value, err.allowed, printable(source)) from None
    return data


def read_scene_table(path: str | os.PathLike) -> dict[str, Any]:
    """:func:`read_scene_text` then :func:`parse_scene_text`: the checked TOML table of a scene file."""
    return parse_scene_text(read_scene_text(path), os.fspath(path))


def scene_description(path: Path) -> str:
    """The ``description`` of a scene file for ``coopctrl list``, or ``"(unreadable: ...)"``."""
    try:
        description = read_scene_table(path).get("description", "")
    except ScenarioError as err:
        return f"(unreadable: {err.allowed if not err.path else err})"
    return " ".join(description.split()) if isinstance(description, str) else ""
