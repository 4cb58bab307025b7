"""Time-series metrics of a campaign: mean ± 95 % CI over the seeds at every time, and figures.

A run may return a series as a metric named ``*_series`` holding a JSON list of numbers (one per
sample time), e.g. the combined filter entropy at every scan of a road tracking episode. The runs
of a group (equal parameters) are averaged sample by sample over their common length, with a
Student-t 95 % interval, and drawn one line per group with its band (paper 000, Fig. 11), with
horizontal reference lines (a lower bound) where the experiment gives them.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from searchtrack.core.types import FloatArray
from searchtrack.sim.campaigns.experiments import Experiment
from searchtrack.sim.campaigns.report import group_order
from searchtrack.sim.campaigns.stats import t_half_width
from searchtrack.sim.figure_style import DPI, pyplot, save_png

Row = Mapping[str, Any]

SERIES_SUFFIX = "_series"


@dataclass(frozen=True)
class SeriesSummary:
    """One group's series: its label, runs averaged, mean and 95 % half-width per sample."""

    label: str
    params: tuple[tuple[str, Any], ...]
    runs: int
    mean: FloatArray
    half_width: FloatArray


def parse(value: Any) -> FloatArray | None:
    """A series value as a float array, or ``None`` when it is not a JSON list of numbers."""
    if not isinstance(value, str):
        return None
    try:
        data = json.loads(value)
        arr = np.asarray(data, dtype=np.float64)
    except (ValueError, TypeError):
        return None
    return arr if arr.ndim == 1 else None


def series_metrics(rows: Sequence[Row], metrics: Sequence[str]) -> list[str]:
    """The metrics of ``metrics`` that are series in ``rows``."""
    return [m for m in metrics if m.endswith(SERIES_SUFFIX)
            and any(parse(r.get(m)) is not None for r in rows)]


def summarise_series(rows: Sequence[Row], group_keys: Sequence[str],
                     metric: str) -> list[SeriesSummary]:
    """Per group of ``rows`` (by ``group_keys``, ``ok`` runs only) the mean and 95 % half-width
    of ``metric`` at every sample of the runs' common length."""
    groups: dict[tuple[Any, ...], list[FloatArray]] = {}
    for row in rows:
        series = parse(row.get(metric)) if row.get("status") == "ok" else None
        if series is not None and series.size:
            groups.setdefault(tuple(row.get(k) for k in group_keys), []).append(series)
    out = []
    for values, members in sorted(groups.items(), key=lambda item: group_order(item[0])):
        n = min(s.size for s in members)
        stack = np.stack([s[:n] for s in members])
        mean = stack.mean(axis=0)
        half = (t_half_width(stack.std(axis=0, ddof=1), stack.shape[0]) if stack.shape[0] > 1
                else np.zeros(n))
        params = tuple(zip(group_keys, values, strict=True))
        label = ", ".join(f"{k}={v}" for k, v in params) or metric
        out.append(SeriesSummary(label, params, len(members), mean, np.asarray(half)))
    return out


def plot_series(summaries: Sequence[SeriesSummary], path: Path, *, step: float = 1.0,
                x_label: str = "sample", y_label: str = "", title: str = "",
                references: Mapping[str, float] | None = None) -> Path:
    """Each group's mean with its 95 % band against time (sample ``i`` at ``(i + 1)·step``),
    with horizontal reference lines; written atomically as PNG."""
    plt = pyplot()

    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=DPI)
    for s in summaries:
        t = step * (np.arange(s.mean.size) + 1)
        ax.plot(t, s.mean, label=f"{s.label} ({s.runs} runs)")
        ax.fill_between(t, s.mean - s.half_width, s.mean + s.half_width, alpha=0.2)
    for label, value in (references or {}).items():
        ax.axhline(value, color="k", linestyle="--", linewidth=1.0)
        ax.annotate(label, (0.01, value), xycoords=("axes fraction", "data"), fontsize=7,
                    va="bottom")
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    ax.set_title(title)
    ax.legend(fontsize=7)
    return save_png(fig, path)


def write_series_figures(name: str, experiment: Experiment, group_keys: Sequence[str],
                         rows: Sequence[Row], metrics: Sequence[str], folder: Path) -> list[Path]:
    """One PNG per series metric of ``rows``: every group's mean and band over the experiment's
    time axis, with its reference lines (those of the first group; they are drawn when all
    groups share them)."""
    axis = experiment.time_axis
    out = []
    for metric in series_metrics(rows, metrics):
        summaries = summarise_series(rows, group_keys, metric)
        if not summaries:
            continue
        refs: dict[str, float] = {}
        if experiment.references is not None:
            per_group = [experiment.reference_lines(_fixed(rows, group_keys) | dict(s.params))
                         for s in summaries]
            refs = per_group[0] if all(r == per_group[0] for r in per_group) else {}
        label = metric.removesuffix(SERIES_SUFFIX)
        out.append(plot_series(summaries, folder / f"{name}-{metric}.png", step=axis.step,
                               x_label=axis.label, y_label=label, references=refs,
                               title=f"{name}: {label} over time (mean, 95 % CI)"))
    return out


def _fixed(rows: Sequence[Row], group_keys: Sequence[str]) -> dict[str, Any]:
    """The parameters of the first row that are not grid keys (the campaign's settings)."""
    return {k: v for k, v in (rows[0].items() if rows else ()) if k not in group_keys}
