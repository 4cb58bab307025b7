"""Running the command in-process the way the bad-input and junk tests do: the exit status, with
argparse's own exit taken as one, and a command run on a file written from junk bytes or text."""

from __future__ import annotations

import tempfile
from collections.abc import Callable
from pathlib import Path

from searchtrack.cli import main


def run_main(argv: list[str]) -> int:
    """``searchtrack argv`` in-process: its exit status (argparse exits with 2 itself)."""
    try:
        return main(argv)
    except SystemExit as exc:  # argparse rejects the option itself
        return int(exc.code) if isinstance(exc.code, int) else 2


def run_on_file(argv: Callable[[Path, Path], list[str]], name: str, data: str | bytes) -> int:
    """Write ``data`` as ``name`` in a fresh folder and run ``argv(path, folder)`` on it."""
    with tempfile.TemporaryDirectory() as folder:
        tmp = Path(folder)
        path = tmp / name
        if isinstance(data, bytes):
            path.write_bytes(data)
        else:
            path.write_text(data, encoding="utf-8", errors="surrogatepass")
        return run_main(argv(path, tmp))
