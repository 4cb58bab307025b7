"""Time-series metrics: per-sample mean and 95 % interval, and their figure."""

from __future__ import annotations

import json
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import pytest

from searchtrack.sim.campaigns import series
from searchtrack.sim.campaigns.experiments import Experiment, Metric, Param, Reference, TimeAxis
from searchtrack.sim.campaigns.series import (
    parse,
    plot_series,
    series_metrics,
    summarise_series,
    write_series_figures,
)


def _row(planner: str, values: list[float], status: str = "ok") -> dict[str, object]:
    return {"planner": planner, "status": status, "map": "m", "entropy_series": json.dumps(values),
            "mean_entropy": float(np.mean(values))}


ROWS = [_row("a", [3.0, 2.0, 1.0]), _row("a", [5.0, 4.0, 3.0, 9.0]), _row("b", [1.0, 1.0]),
        _row("b", [7.0, 7.0], status="error")]


def test_parse_takes_json_lists_of_numbers_only() -> None:
    assert np.array_equal(parse("[1, 2.5]"), [1.0, 2.5])  # type: ignore[arg-type]
    for junk in ("nope", "[[1, 2], [3]]", "{\"a\": 1}", 3.0, None, "[\"x\"]"):
        assert parse(junk) is None


def test_series_metrics_are_the_listed_series_columns() -> None:
    assert series_metrics(ROWS, ["mean_entropy", "entropy_series"]) == ["entropy_series"]
    assert series_metrics(ROWS, ["mean_entropy"]) == []


def test_groups_average_over_their_common_length_and_skip_failures() -> None:
    a, b = summarise_series(ROWS, ["planner"], "entropy_series")
    assert (a.label, a.runs, b.runs) == ("planner=a", 2, 1)
    assert np.allclose(a.mean, [4.0, 3.0, 2.0])
    # two samples 2 apart: sd = √2, half-width = t(0.975, 1)·sd/√2 = 12.706
    assert np.allclose(a.half_width, 12.7062, atol=1e-3)
    assert np.allclose(b.mean, [1.0, 1.0]) and np.allclose(b.half_width, 0.0)


def _series_experiment(reference: Reference | None = None) -> Experiment:
    return Experiment("toy_series", (Param("planner", str, "a"), Param("map", str, "m")),
                      {"mean_entropy": Metric(float), "entropy_series": Metric(str)},
                      lambda p, s: {"mean_entropy": 0.0, "entropy_series": "[]"},
                      references=reference, time_axis=TimeAxis(2.0, "time (s)"))


def test_figures_are_written_with_reference_lines(tmp_path: Path) -> None:
    seen: list[dict[str, object]] = []

    def reference(params: Mapping[str, object]) -> dict[str, float]:
        seen.append(dict(params))
        return {"bound": 0.5}

    paths = write_series_figures("c", _series_experiment(reference), ["planner"], ROWS,
                                 ["mean_entropy", "entropy_series"], tmp_path)
    assert [p.name for p in paths] == ["c-entropy_series.png"]
    assert paths[0].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert {p["planner"] for p in seen} == {"a", "b"} and all(p["map"] == "m" for p in seen)


def test_figures_take_the_experiments_time_axis_and_references(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The figure is drawn on the experiment's time axis with its reference lines, and only
    with lines all groups share."""
    drawn: list[dict[str, object]] = []

    def plot(summaries: object, path: Path, **kwargs: object) -> Path:
        drawn.append(kwargs)
        return path

    monkeypatch.setattr(series, "plot_series", plot)
    write_series_figures("c", _series_experiment(lambda p: {"bound": 0.5}), ["planner"], ROWS,
                         ["entropy_series"], tmp_path)
    write_series_figures("c", _series_experiment(lambda p: {"b": float(p["planner"] == "a")}),
                         ["planner"], ROWS, ["entropy_series"], tmp_path)
    write_series_figures("c", _series_experiment(), ["planner"], ROWS, ["entropy_series"],
                         tmp_path)
    assert [(d["step"], d["x_label"], d["references"]) for d in drawn] == [
        (2.0, "time (s)", {"bound": 0.5}), (2.0, "time (s)", {}), (2.0, "time (s)", {})]


def test_every_experiments_references_reach_the_figure(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """For every registered experiment, a series figure of runs at its defaults is drawn on its
    time axis with the reference lines it gives for them (paper 000's Theorem 1 bound)."""
    from searchtrack.sim.campaigns.experiments import EXPERIMENTS

    drawn: list[dict[str, object]] = []

    def plot(summaries: object, path: Path, **kwargs: object) -> Path:
        drawn.append(kwargs)
        return path

    monkeypatch.setattr(series, "plot_series", plot)
    with_lines = set()
    for exp in EXPERIMENTS.values():
        rows = [{**exp.resolve({}), "status": "ok", "seed": s, "x_series": "[1.0, 2.0]"}
                for s in (0, 1)]
        drawn.clear()
        write_series_figures("c", exp, [], rows, ["x_series"], tmp_path)
        (kwargs,) = drawn
        assert (kwargs["step"], kwargs["x_label"]) == (exp.time_axis.step, exp.time_axis.label)
        assert kwargs["references"] == exp.reference_lines(rows[0])
        if kwargs["references"]:
            with_lines.add(exp.name)
    assert with_lines == {"road_tracking_episode"}
    road = EXPERIMENTS["road_tracking_episode"]
    assert (road.time_axis.step, road.time_axis.label) == (1.0, "time (s)")


def test_plot_series_without_references(tmp_path: Path) -> None:
    path = plot_series(summarise_series(ROWS, [], "entropy_series"), tmp_path / "x.png")
    assert path.is_file()
