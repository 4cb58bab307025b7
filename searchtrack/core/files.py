"""Reading input files safely and writing outputs atomically.

Inputs: every failure names the file, and nothing is read past a limit.

:func:`open_input` refuses what is not a regular file (a folder, ``/dev/zero``, a pipe), files
larger than a limit, and decompresses bzip2 by its magic bytes while counting what it inflates;
:func:`read_text` decodes UTF-8 and reports an encoding error with its line. Truncated or
corrupt compressed data, unreadable files and size overruns all raise
:class:`~searchtrack.core.errors.ParseError` naming the file.

Outputs: :func:`atomic_path` and :func:`write_text_atomic` write beside the target and rename,
so a file is either whole or absent, whatever interrupts the write.
"""

from __future__ import annotations

import bz2
import contextlib
import io
import json
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO, Any

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
    p = Path(path)
    if not p.exists():
        raise ParseError(p, None, None, "no such file")
    if not p.is_file():
        raise ParseError(p, None, None, "not a regular file")
    try:
        size = p.stat().st_size
        with p.open("rb") as raw:
            magic = raw.read(3)
            raw.seek(0)
            packed = magic == b"BZh"
            if not packed and size > max_bytes:
                raise ParseError(p, None, None, f"is {_mib(size)}, larger than the "
                                 f"{_mib(max_bytes)} an input may hold")
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


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside ``path`` to write to (its folder made if missing); renamed onto
    ``path`` (atomically, on the same file system) when the block ends, removed if it raises.
    A reader never sees a half-written file; an interrupted write leaves the old file (or none).
    """
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent)
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
