"""Mission figures: the map and MOC plots are written as PNG files and leave no figure open."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import matplotlib.image
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure

from searchtrack.sim.roads.figures import plot_map, plot_moc
from tests.sim.roads.mission_logs import empty_log, two_step_log

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


def _legends(monkeypatch: pytest.MonkeyPatch) -> list[list[str]]:
    """Record the legend entries of the first axes of every figure pyplot closes."""
    entries: list[list[str]] = []
    close = plt.close

    def spy(fig: Figure) -> None:
        legend = fig.axes[0].get_legend()
        entries.append([t.get_text() for t in legend.get_texts()] if legend else [])
        close(fig)

    monkeypatch.setattr(plt, "close", spy)
    return entries


def test_every_marker_is_in_the_legend(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The map's legend names the UAV paths and end markers, the targets and their end markers;
    the MOC plot's legend (inside the axes) names both curves."""
    entries = _legends(monkeypatch)
    log = two_step_log()
    plot_map(log, tmp_path / "map.png")
    plot_moc(log, tmp_path / "moc.png")
    uavs = [f"UAV {j + 1}" for j in range(log.uav_xy_m.shape[1])]
    assert set(uavs) | {"UAVs at the end"} <= set(entries[0])
    if log.target_xy_m.shape[1]:
        assert {"targets", "targets at the end"} <= set(entries[0])
    assert entries[1] == ["MOC (valid trackers / targets)", "trackers"]


def test_map_axes_hold_every_path(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A UAV that flew beyond the roads is not cropped: the axes hold every path."""
    limits: list[tuple[tuple[float, float], tuple[float, float]]] = []
    close = plt.close

    def spy(fig: Figure) -> None:
        limits.append((fig.axes[0].get_xlim(), fig.axes[0].get_ylim()))
        close(fig)

    monkeypatch.setattr(plt, "close", spy)
    log = two_step_log()
    far = log.uav_xy_m.copy()
    far[-1, 0] = far.max(axis=(0, 1)) + 5000.0
    plot_map(dataclasses.replace(log, uav_xy_m=far), tmp_path / "map.png")
    (x0, x1), (y0, y1) = limits[0]
    assert x0 <= far[..., 0].min() and x1 >= far[..., 0].max()
    assert y0 <= far[..., 1].min() and y1 >= far[..., 1].max()
