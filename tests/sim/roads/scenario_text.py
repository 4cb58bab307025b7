"""A small grid scenario as TOML text, and a writer, shared by the scenario tests."""

from __future__ import annotations

from pathlib import Path

GRID = """
name = "grid"
duration_s = 3.0
[map]
grid = { rows = 4, cols = 4, block_m = 100.0 }
[uavs]
count = 2
"""


def write(tmp_path: Path, text: str) -> Path:
    """Write ``text`` to a scenario file and return its path."""
    path = tmp_path / "s.toml"
    path.write_text(text, encoding="utf-8")
    return path
