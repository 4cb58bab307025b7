"""Mission figures: the map and MOC plots are written as PNG files and leave no figure open."""

from __future__ import annotations

from pathlib import Path

import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure

from searchtrack.sim.figures import plot_map, plot_moc
from tests.sim.mission_logs import empty_log, two_step_log

PNG = b"\x89PNG\r\n\x1a\n"


def test_map_is_a_png(tmp_path: Path) -> None:
    """plot_map writes an RGBA PNG at the given path, returns that path and closes its figure."""
    path = plot_map(two_step_log(), tmp_path / "map.png")
    assert path == tmp_path / "map.png"
    assert path.read_bytes()[:8] == PNG
    image = matplotlib.image.imread(path)
    assert image.ndim == 3 and image.shape[2] == 4 and np.ptp(image) > 0  # not blank
    assert plt.get_fignums() == []


def test_moc_is_a_png_of_the_figure_size(tmp_path: Path) -> None:
    """plot_moc writes a 7 × 3.5 in figure at 110 dpi: a 770 × 385 pixel PNG."""
    path = plot_moc(two_step_log(), tmp_path / "moc.png")
    assert path.read_bytes()[:8] == PNG
    assert matplotlib.image.imread(path).shape[:2] == (385, 770)
    assert plt.get_fignums() == []


def _titles(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Record the axes title of every figure pyplot closes."""
    titles: list[str] = []
    close = plt.close

    def spy(fig: Figure) -> None:
        titles.append(fig.axes[0].get_title())
        close(fig)

    monkeypatch.setattr(plt, "close", spy)
    return titles


def test_map_title_has_the_final_time(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The map of a two-step log is titled with the scenario, strategy and last step time."""
    titles = _titles(monkeypatch)
    plot_map(two_step_log(), tmp_path / "map.png")
    assert titles == ["rec: search_and_loiter, t = 0.6 s"]


def test_map_of_a_log_without_steps(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A mission stopped before its first step still gets a map, titled without a time."""
    titles = _titles(monkeypatch)
    path = plot_map(empty_log(), tmp_path / "map.png")
    assert path.read_bytes()[:8] == PNG
    assert titles == ["rec: search_and_loiter"]
    assert list(tmp_path.iterdir()) == [path]
