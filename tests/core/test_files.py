"""Input files: every failure names the file; nothing is read past the limit."""

from __future__ import annotations

import bz2
import os
from pathlib import Path

import pytest

from searchtrack.core.errors import ParseError
from searchtrack.core.files import open_input, read_json, read_text, write_text_atomic


def test_plain_and_bzip2_text_read_alike(tmp_path: Path) -> None:
    """A file and its bzip2 form give the same text."""
    text = "héllo\nworld\n"
    (tmp_path / "a.txt").write_text(text, encoding="utf-8")
    (tmp_path / "a.txt.bz2").write_bytes(bz2.compress(text.encode()))
    assert read_text(tmp_path / "a.txt") == read_text(tmp_path / "a.txt.bz2") == text


@pytest.mark.parametrize(("make", "reason"), [
    (lambda d: d / "missing", "no such file"),
    (lambda d: d, "not a regular file"),
    (lambda d: Path("/dev/zero"), "not a regular file"),
    (lambda d: _write(d / "t.bz2", bz2.compress(bytes(range(256)) * 3)[:200]),
     "truncated or corrupt"),
    (lambda d: _write(d / "b.txt", b"ok\n\xff\xfe"), "line 2: not UTF-8"),
    (lambda d: _write(d / "big.txt", b"x" * 2000), "larger than the 1000 bytes"),
    (lambda d: _write(d / "bomb.bz2", bz2.compress(b"x" * 5000)), "larger than the 1000 bytes"),
])
def test_bad_files_name_the_file(tmp_path: Path, make, reason: str) -> None:  # type: ignore[no-untyped-def]
    """Missing, special, truncated, non-UTF-8 and oversized (also once inflated) files raise
    ParseError naming the file."""
    path = make(tmp_path)
    with pytest.raises(ParseError) as err:
        read_text(path, max_bytes=1000)
    assert str(path) in str(err.value) and reason in str(err.value)


def test_open_input_streams_within_the_limit(tmp_path: Path) -> None:
    """A stream reads to the end of a file under the limit."""
    path = _write(tmp_path / "s.bz2", bz2.compress(b"abc" * 100))
    with open_input(path, max_bytes=300) as stream:
        assert stream.read() == b"abc" * 100


def _write(path: Path, data: bytes) -> Path:
    path.write_bytes(data)
    return path


@pytest.mark.parametrize(("text", "reason"), [
    ('{"a": 1,\n "b": }', "not valid JSON: Expecting value"),
    ("[" * 100_000 + "]" * 100_000, "nested too deeply"),
    ("1" * 5000, "not valid JSON: Exceeds the limit"),
])
def test_read_json_names_the_file_for_text_that_is_not_json(tmp_path: Path, text: str,
                                                            reason: str) -> None:
    """Broken syntax (with its line), deep nesting and an over-long integer are parse errors
    naming the file, never a traceback."""
    path = tmp_path / "bad.json"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ParseError, match=reason) as info:
        read_json(path)
    assert str(path) in str(info.value)


def test_read_json_reads_a_value(tmp_path: Path) -> None:
    path = tmp_path / "good.json"
    path.write_text('{"a": [1, 2.5]}', encoding="utf-8")
    assert read_json(path) == {"a": [1, 2.5]}


@pytest.mark.parametrize("mask", [0o022, 0o077, 0o002])
def test_atomic_writes_follow_the_umask(tmp_path: Path, mask: int) -> None:
    """An output gets the mode of any new file under the user's umask, not mkstemp's 0600; the
    umask itself is left as it was."""
    old = os.umask(mask)
    try:
        out = write_text_atomic(tmp_path / "sub" / "out.txt", "x")
        assert os.umask(mask) == mask
    finally:
        os.umask(old)
    assert out.stat().st_mode & 0o777 == 0o666 & ~mask
    assert out.read_text() == "x" and [p.name for p in out.parent.iterdir()] == ["out.txt"]
