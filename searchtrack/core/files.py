"""Reading input files safely and writing outputs atomically.

Inputs: every failure names the file, and nothing is read past a limit.

:func:`open_input` refuses what is not a regular file (a folder, ``/dev/zero``, a pipe), files
larger than a limit, and decompresses bzip2 by its magic bytes while counting what it inflates;
:func:`read_text` decodes UTF-8 and reports an encoding error with its line. Truncated or
corrupt compressed data, unreadable files and size overruns all raise
:class:`~searchtrack.core.errors.ParseError` naming the file.

:func:`read_npz` reads a NumPy ``.npz`` archive, checking every array's header against the
bytes the archive holds before allocating it, so a short file cannot claim a huge array.

Outputs: :func:`atomic_path` and :func:`write_text_atomic` write beside the target and rename,
so a file is either whole or absent, whatever interrupts the write.
"""

from __future__ import annotations

import bz2
import contextlib
import io
import json
import math
import os
import struct
import tempfile
import tokenize
import zipfile
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import ParseError

#: Default limit on what an input may hold once decompressed (bytes): far above any map, instance
#: or recording this library reads (the bundled city map inflates to 120 kB).
MAX_INPUT_BYTES = 256 * 2**20


def _mib(n: int) -> str:
    return f"{n / 2**20:.0f} MiB" if n >= 2**20 else f"{n} bytes"


class _Bounded(io.RawIOBase):
    """A binary stream that raises once more than ``limit`` bytes have been read from it."""

    def __init__(self, inner: IO[bytes], path: Path, limit: int) -> None:
        self.inner, self.path, self.limit, self.count = inner, path, limit, 0

    def readable(self) -> bool:
        return True

    def readinto(self, buffer: bytearray | memoryview) -> int:  # type: ignore[override]
        data = self.inner.read(len(buffer))
        self.count += len(data)
        if self.count > self.limit:
            raise ParseError(self.path, None, None,
                             f"larger than the {_mib(self.limit)} an input may hold")
        buffer[: len(data)] = data
        return len(data)


def read_json(path: str | Path, *, max_bytes: int = MAX_INPUT_BYTES) -> Any:
    """The file's JSON value (read as :func:`read_text`).

    Raises
    ------
    ParseError
        As :func:`read_text`; for text that is not JSON (naming the line), nested too deeply, or
        holding an integer of more digits than Python converts.
    """
    text = read_text(path, max_bytes=max_bytes)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise ParseError(path, exc.lineno, None, f"not valid JSON: {exc.msg}") from None
    except RecursionError:
        raise ParseError(path, None, None, "not valid JSON: nested too deeply") from None
    except ValueError as exc:
        raise ParseError(path, None, None, f"not valid JSON: {exc}") from None


def _regular_file(path: str | Path) -> Path:
    """``path`` as a Path, or a ParseError when it does not exist or is not a regular file."""
    p = Path(path)
    if not p.exists():
        raise ParseError(p, None, None, "no such file")
    if not p.is_file():
        raise ParseError(p, None, None, "not a regular file")
    return p


def _too_large(p: Path, size: int, max_bytes: int) -> ParseError:
    """The error of an input of ``size`` bytes over ``max_bytes``."""
    return ParseError(p, None, None, f"is {_mib(size)}, larger than the {_mib(max_bytes)} an "
                      "input may hold")


@contextlib.contextmanager
def open_input(path: str | Path, *,
               max_bytes: int = MAX_INPUT_BYTES) -> Iterator[io.BufferedReader[Any]]:
    """The file as a binary stream, bzip2 decompressed when it starts with ``BZh``, read at
    most ``max_bytes`` (after decompression).

    Raises
    ------
    ParseError
        No such file, not a regular file, over the limit, unreadable, or truncated / corrupt
        compressed data (also when that is found while the caller reads).
    """
    p = _regular_file(path)
    try:
        size = p.stat().st_size
        with p.open("rb") as raw:
            magic = raw.read(3)
            raw.seek(0)
            packed = magic == b"BZh"
            if not packed and size > max_bytes:
                raise _too_large(p, size, max_bytes)
            inner: IO[bytes] = bz2.BZ2File(raw) if packed else raw  # type: ignore[assignment]
            with io.BufferedReader(_Bounded(inner, p, max_bytes)) as stream:
                yield stream
    except ParseError:
        raise
    except EOFError:
        raise ParseError(p, None, None, "truncated or corrupt compressed data (the bzip2 stream "
                         "ends early)"
                         ) from None
    except OSError as exc:
        reason = str(exc) or type(exc).__name__
        if "Invalid data stream" in reason:
            reason = "corrupt compressed data (not a valid bzip2 stream)"
        raise ParseError(p, None, None, f"cannot read: {reason}") from None


def read_text(path: str | Path, *, max_bytes: int = MAX_INPUT_BYTES) -> str:
    """The whole file decoded as UTF-8 (bzip2 decompressed when packed), within ``max_bytes``.

    Raises
    ------
    ParseError
        As :func:`open_input`, and for bytes that are not UTF-8 (naming the line).
    """
    with open_input(path, max_bytes=max_bytes) as stream:
        data = stream.read()
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise ParseError(path, line, None, f"not UTF-8 text (byte {exc.start}: "
                         f"{data[exc.start:exc.start + 1]!r})") from None


def _umask() -> int:
    """The process's file-creation mask: read from ``/proc/self/status`` where Linux gives it
    (nothing changes it meanwhile), else by setting it and restoring it at once."""
    try:
        with open("/proc/self/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to (its folder made if missing), with the mode a
    new file gets under the user's umask; renamed onto ``path`` (atomically, on the same file
    system) when the block ends, removed if it raises.
    A reader never sees a half-written file; an interrupted write leaves the old file (or none).
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())   # mkstemp's 0600 would leak into the output
    finally:
        os.close(fd)
    temp = Path(name)
    try:
        yield temp
        os.replace(temp, target)
    finally:
        temp.unlink(missing_ok=True)


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (see :func:`atomic_path`)."""
    with atomic_path(path) as temp:
        temp.write_text(text, encoding="utf-8")
    return Path(path)


#: Most arrays :func:`read_npz` reads from one archive.
MAX_NPZ_ARRAYS = 64

_NPZ_ERRORS = (zipfile.BadZipFile, zlib.error, EOFError, OSError, ValueError, struct.error,
               NotImplementedError, RuntimeError)
"""What a corrupt archive raises inside :mod:`zipfile` and :mod:`numpy.lib.format` (a bad
magic or header, a short member, a failed CRC, an unknown compression or an encrypted member)."""

_NPY_HEADER_ERRORS = (*_NPZ_ERRORS, tokenize.TokenError, SyntaxError, RecursionError, TypeError,
                      LookupError, AttributeError)
"""What NumPy's parser of the Python-literal ``.npy`` header also raises on crafted text."""


def _npy_header(fp: IO[bytes]) -> tuple[tuple[int, ...], np.dtype[Any]]:
    """The shape and dtype an ``.npy`` stream declares (read, not allocated)."""
    version = np.lib.format.read_magic(fp)
    if version == (1, 0):
        shape, _, dtype = np.lib.format.read_array_header_1_0(fp)
    elif version == (2, 0):
        shape, _, dtype = np.lib.format.read_array_header_2_0(fp)
    else:
        raise ValueError(f".npy format version {version[0]}.{version[1]} is not supported")
    return tuple(shape), dtype


def _npz_member(path: Path, archive: zipfile.ZipFile, info: zipfile.ZipInfo) -> tuple[str, int]:
    """The array's name and the bytes it declares, checked against what the member holds."""
    if not info.filename.endswith(".npy"):
        raise ParseError(path, None, info.filename, "not a .npy array (an .npz holds only those)")
    name = info.filename[:-4]
    try:
        with archive.open(info) as fp:
            shape, dtype = _npy_header(fp)
            held = info.file_size - fp.tell()
    except _NPY_HEADER_ERRORS as exc:
        raise ParseError(path, None, name, f"not a readable .npy array header ({exc})") from None
    if dtype.hasobject:
        raise ParseError(path, None, name, "holds Python objects (pickles), which are not read")
    if any(n < 0 for n in shape):
        raise ParseError(path, None, name, f"declares a negative dimension {shape}")
    declared = math.prod(shape) * max(dtype.itemsize, 1)
    if declared > held:
        raise ParseError(path, None, name, f"declares shape {shape} of {dtype} ({declared} bytes) "
                         f"but the archive holds {max(held, 0)} bytes for it")
    return name, declared


def read_npz(path: str | Path, *, max_bytes: int = MAX_INPUT_BYTES,
             max_arrays: int = MAX_NPZ_ARRAYS) -> dict[str, NDArray[Any]]:
    """The arrays of NumPy ``.npz`` archive ``path`` by name (``NAME.npy`` members, no pickles).

    Nothing is allocated before every member's ``.npy`` header has been read and checked: the
    bytes an array declares (its shape times its item size) must fit in what its member holds
    uncompressed, and all arrays together in ``max_bytes``; the file itself must be a regular
    file of at most ``max_bytes`` holding at most ``max_arrays`` members.

    Raises
    ------
    ParseError
        Naming the file, and the array (``field``) when one member is at fault: no such file,
        not a regular file, too large, not a zip archive, a member that is not ``.npy``, holds
        objects, declares more than it holds, or is corrupt (bad header, short data, failed CRC).
    """
    p = _regular_file(path)
    name: str | None = None
    try:
        if (size := p.stat().st_size) > max_bytes:
            raise _too_large(p, size, max_bytes)
        with zipfile.ZipFile(p) as archive:
            members = archive.infolist()
            if len(members) > max_arrays:
                raise ParseError(p, None, None, f"holds {len(members)} members, more than the "
                                 f"{max_arrays} arrays an .npz input may hold")
            total = 0
            for info in members:
                name, declared = _npz_member(p, archive, info)
                total += declared
                if total > max_bytes:
                    raise ParseError(p, None, name, f"the arrays declare more than the "
                                     f"{_mib(max_bytes)} an input may hold")
            arrays: dict[str, NDArray[Any]] = {}
            for info in members:
                name = info.filename[:-4]
                with archive.open(info) as fp:
                    arrays[name] = np.lib.format.read_array(fp, allow_pickle=False)
            return arrays
    except ParseError:
        raise
    except _NPZ_ERRORS as exc:
        raise ParseError(p, None, name, f"not a readable .npz archive ({exc})") from None
