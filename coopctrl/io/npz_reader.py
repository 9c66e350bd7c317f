"""Reading an ``.npz`` archive that may be damaged or hostile, without trusting what it claims.

``numpy.load`` allocates the array an entry's header describes before reading it: a header that
claims 149 GiB is a ``MemoryError`` (or a machine that swaps), a truncated file a ``zipfile`` or
``EOFError`` deep inside numpy. :func:`read_npz` checks every claim against what is on disk first:
the entry names, the zip directory, each header's shape and type against the entry's real size, and
the total against the memory available; the zip's CRC-32 is checked as each entry is read to its end.
Every failure is one :class:`DamagedFileError` naming the file and what is wrong.
"""

from __future__ import annotations

import math
import os
import struct
import zipfile
import zlib
from typing import Iterable

import numpy as np
from numpy.lib import format as npy_format

from coopctrl.errors import CoopctrlError

#: Largest header of an entry [B] (numpy writes about 128 bytes).
MAX_HEADER_BYTES = 10_000


class DamagedFileError(CoopctrlError, ValueError):
    """A file that coopctrl wrote is damaged or is not what it should be (exit 2: bad input).

    Attributes:
        path: The file.
        problem: What is wrong, one line.
    """

    def __init__(self, path: str | os.PathLike, problem: str, fix: str = "",
                 what: str = "is damaged or not a coopctrl file"):
        self.path = os.fspath(path)
        self.problem = problem
        tail = f"; {fix}" if fix else ""
        super().__init__(f"{self.path} {what}: {problem}{tail}")


def _size_text(n: float) -> str:
    for unit, size in (("TiB", 2.0**40), ("GiB", 2.0**30), ("MiB", 2.0**20), ("KiB", 2.0**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def read_npz(path: str | os.PathLike, required: Iterable[str], optional: Iterable[str] = (),
             max_bytes: float = math.inf, fix: str = "") -> dict[str, np.ndarray]:
    """The arrays of the ``.npz`` file ``path``, by name (without ``.npy``).

    Args:
        path: The archive.
        required: Entries that must be present.
        optional: Entries that may be present; any other entry is refused (not written by coopctrl).
        max_bytes: Largest total of the arrays' data [B] (the memory that may be spent on them).
        fix: How to fix a damaged file, appended to every message.

    Raises:
        DamagedFileError: the file is not a readable zip of ``.npy`` entries, an entry is missing or
            unknown, a header is malformed, claims more data than its entry holds, holds Python
            objects, or the whole exceeds ``max_bytes``; a CRC-32 does not match.
        OSError: the file cannot be opened (missing, a directory, no permission).
    """
    required, optional = tuple(required), tuple(optional)
    known = set(required) | set(optional)

    def damaged(problem: str) -> DamagedFileError:
        return DamagedFileError(path, problem, fix)

    size = os.stat(path).st_size
    if size == 0:
        raise damaged("it is empty (0 bytes)")
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, ValueError, struct.error) as exc:
        raise damaged(f"not a readable zip archive ({_reason(exc)})") from None
    with archive:
        infos = {}
        for info in archive.infolist():
            name = info.filename[:-4] if info.filename.endswith(".npy") else None
            if name is None or name not in known:
                raise damaged(f"unknown entry {info.filename!r} (coopctrl writes no such entry)")
            if name in infos:
                raise damaged(f"entry {info.filename!r} appears twice")
            infos[name] = info
        missing = [name for name in required if name not in infos]
        if missing:
            raise damaged(f"entry {missing[0] + '.npy'!r} is missing")
        claimed = sum(info.file_size for info in infos.values())
        if claimed > max_bytes:
            raise damaged(f"its entries claim {_size_text(claimed)} uncompressed, more than the "
                          f"{_size_text(max_bytes)} that may be spent reading it")
        if any(info.compress_size > size for info in infos.values()):
            raise damaged("an entry claims more compressed bytes than the file holds")
        return {name: _read_entry(archive, info, damaged) for name, info in infos.items()}


def _reason(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def _read_entry(archive: zipfile.ZipFile, info: zipfile.ZipInfo, damaged) -> np.ndarray:
    entry = info.filename
    try:
        with archive.open(info) as handle:
            try:
                version = npy_format.read_magic(handle)
                if version == (1, 0):
                    shape, fortran, dtype = npy_format.read_array_header_1_0(handle, max_header_size=MAX_HEADER_BYTES)
                elif version == (2, 0):
                    shape, fortran, dtype = npy_format.read_array_header_2_0(handle, max_header_size=MAX_HEADER_BYTES)
                else:
                    raise damaged(f"entry {entry!r} has an unknown .npy version {version}")
            except (ValueError, SyntaxError, TypeError, struct.error, UnicodeDecodeError) as exc:
                raise damaged(f"entry {entry!r} has a malformed header ({_reason(exc)})") from None
            if dtype.hasobject:
                raise damaged(f"entry {entry!r} holds Python objects, which coopctrl never writes")
            if any(d < 0 for d in shape):
                raise damaged(f"entry {entry!r} claims a negative shape {shape}")
            count = math.prod(shape)
            nbytes = count * dtype.itemsize
            header = handle.tell()
            holds = info.file_size - header
            if nbytes != holds:
                raise damaged(f"entry {entry!r} claims shape {shape} of {dtype} ({_size_text(nbytes)}) but holds "
                              f"{_size_text(max(holds, 0))} of data")
            data = handle.read(nbytes)
            if len(data) != nbytes or handle.read(1):
                raise damaged(f"entry {entry!r} is truncated")
    except DamagedFileError:
        raise
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, NotImplementedError, struct.error) as exc:
        raise damaged(f"entry {entry!r} cannot be read ({_reason(exc)})") from None
    array = np.frombuffer(bytearray(data), dtype=dtype, count=count)
    return array.reshape(shape[::-1]).T if fortran else array.reshape(shape)

