"""The one PNG writer: laid out, written atomically with the user's umask, closed."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from searchtrack.sim.figure_style import DPI, pyplot, save_png

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _png_size(path: Path) -> tuple[int, int]:
    head = path.read_bytes()[:24]
    assert head[:8] == PNG_MAGIC
    return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")


def test_writes_a_png_and_closes_the_figure(tmp_path: Path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(2.0, 1.0), dpi=DPI)
    ax.plot([0, 1], [0, 1])
    out = save_png(fig, tmp_path / "a.png")
    assert out == tmp_path / "a.png"
    assert _png_size(out) == (2 * DPI, DPI)
    assert not plt.fignum_exists(fig.number)
    assert [p.name for p in tmp_path.iterdir()] == ["a.png"]  # no temporary left behind


def test_dpi_and_tight_bbox(tmp_path: Path) -> None:
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(2.0, 1.0), dpi=DPI)
    ax.plot([0, 1], [0, 1])
    assert _png_size(save_png(fig, tmp_path / "b.png", dpi=50)) == (100, 50)
    fig, ax = plt.subplots(figsize=(2.0, 1.0), dpi=DPI)
    ax.text(0.5, 0.5, "x")
    ax.set_axis_off()
    width, height = _png_size(save_png(fig, tmp_path / "c.png", tight_bbox=True))
    assert width < 2 * DPI and height < DPI   # cropped to what is drawn


def test_follows_the_umask(tmp_path: Path) -> None:
    old = os.umask(0o027)
    try:
        fig, _ = pyplot().subplots(figsize=(1.0, 1.0))
        out = save_png(fig, tmp_path / "d.png")
    finally:
        os.umask(old)
    assert out.stat().st_mode & 0o777 == 0o640


def test_a_failed_write_still_closes_the_figure(tmp_path: Path) -> None:
    plt = pyplot()
    fig, _ = plt.subplots(figsize=(1.0, 1.0))
    (tmp_path / "file").write_text("not a folder")
    with pytest.raises(OSError):
        save_png(fig, tmp_path / "file" / "e.png")
    assert not plt.fignum_exists(fig.number)
