"""Where a command writes: every output path is checked before any work, every file written
atomically.

A command resolves its outputs first (:func:`output_file`, :func:`output_dir`): a file path must
not be a folder and the reverse, and the folders it needs must exist or be creatable (the
nearest existing one is a writable folder). A mistyped ``--json`` or ``--out`` therefore fails at
once with exit status 2 instead of after the solve, and a failed run creates nothing: folders
are made when the first file is written, with
:func:`~searchtrack.core.files.write_text_atomic` (temp file + rename).
"""

from __future__ import annotations

import os
from pathlib import Path

from searchtrack.core.errors import SearchtrackError


class OutputError(SearchtrackError):
    """An output path that cannot be written: names the option and the path."""

    def __init__(self, option: str, path: Path, reason: str) -> None:
        super().__init__(f"{option} {path}: {reason}")


def _writable_dir(option: str, folder: Path, shown: Path) -> None:
    """``folder`` is a writable folder, or can be created: its nearest existing ancestor is a
    writable folder (nothing is created here)."""
    existing = folder
    while not existing.exists():
        if existing.parent == existing:
            break
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(option, shown, f"{existing} is a file, not a folder")
    if not os.access(existing, os.W_OK | os.X_OK):
        what = "folder" if existing == folder else "cannot create a folder in"
        raise OutputError(option, shown, f"{what} {existing} is not writable")


def output_file(option: str, path: str | Path) -> Path:
    """``path`` checked as a file to write later: not a folder, its folder created and writable.

    Raises
    ------
    OutputError
        Naming ``option`` (e.g. ``--json``) and the path.
    """
    p = Path(path)
    if p.is_dir():
        raise OutputError(option, p, "is a folder; give a file name")
    if p.exists() and not os.access(p, os.W_OK):
        raise OutputError(option, p, "exists and is not writable")
    _writable_dir(option, p.parent, p)
    return p


def output_dir(option: str, path: str | Path) -> Path:
    """``path`` checked as a folder to write into: created if missing, not a file, writable.

    Raises
    ------
    OutputError
        Naming ``option`` (e.g. ``--out``) and the path.
    """
    p = Path(path)
    _writable_dir(option, p, p)
    return p
