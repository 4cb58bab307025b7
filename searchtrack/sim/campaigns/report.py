"""Campaign reports: mean ± 95 % CI of every metric by group, the paper's claim beside it (as
its experiment states it), and figures with CI bands.

Works on plain rows (one ``dict`` per run, as the results store returns them): the group of a row
is its parameter values (every grid key), the seeds are the samples. Only rows with status
``ok`` count; failed runs are reported by number.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from searchtrack.sim.campaigns.experiments import Experiment
from searchtrack.sim.campaigns.stats import Estimate, estimate
from searchtrack.sim.figure_style import DPI, pyplot, save_png

Row = Mapping[str, Any]


@dataclass(frozen=True)
class GroupSummary:
    """One group of runs (equal parameters): its parameters, runs, failures and estimates."""

    params: tuple[tuple[str, Any], ...]
    runs: int
    failed: int
    metrics: dict[str, Estimate]
    missing: int = 0

    def label(self) -> str:
        """``key=value, ...`` of the group's parameters."""
        return ", ".join(f"{k}={v}" for k, v in self.params) or "(all)"


def summarise(rows: Sequence[Row], group_keys: Sequence[str], metrics: Sequence[str],
              missing: Sequence[Row] = ()) -> list[GroupSummary]:
    """Group ``rows`` by ``group_keys`` (sorted: numbers by value, text alphabetically) and
    estimate every metric over the ``ok`` runs of each group (NaN and missing values dropped);
    ``missing`` are the parameters of the planned runs not run yet, counted in their groups (a
    group with none run is listed with no estimates)."""
    groups: dict[tuple[Any, ...], list[Row]] = {}
    for row in rows:
        groups.setdefault(tuple(row.get(k) for k in group_keys), []).append(row)
    absent: dict[tuple[Any, ...], int] = {}
    for params in missing:
        cell = tuple(params.get(k) for k in group_keys)
        absent[cell] = absent.get(cell, 0) + 1
        groups.setdefault(cell, [])
    out = []
    for values, members in sorted(groups.items(), key=lambda item: group_order(item[0])):
        ok = [r for r in members if r.get("status") == "ok"]
        est = {m: estimate([_number(r.get(m)) for r in ok]) for m in metrics}
        out.append(GroupSummary(tuple(zip(group_keys, values, strict=True)), len(members),
                                len(members) - len(ok), est, absent.get(values, 0)))
    return out


def group_order(values: tuple[Any, ...]) -> tuple[tuple[int, float, str], ...]:
    """A sort key for mixed parameter values: numbers by value, then everything else by text."""
    return tuple((0, float(v), "") if isinstance(v, (int, float)) and not isinstance(v, bool)
                 else (1, 0.0, str(v)) for v in values)


def _number(value: Any) -> float:
    if value is None:
        return math.nan
    try:
        return float(value)
    except (TypeError, ValueError):
        return math.nan


def table_rows(summaries: Sequence[GroupSummary], metrics: Sequence[str]) -> list[list[str]]:
    """Header and one row per group: parameters, runs (failed), ``mean ± half-width`` per
    metric."""
    keys = [k for k, _ in summaries[0].params] if summaries else []
    header = [*keys, "runs", *metrics]
    rows = [header]
    for s in summaries:
        runs = (f"{s.runs}" + (f" of {s.runs + s.missing}" if s.missing else "")
                + (f" ({s.failed} failed)" if s.failed else ""))
        rows.append([*(str(v) for _, v in s.params), runs, *(str(s.metrics[m]) for m in metrics)])
    return rows


def band(estimates: Sequence[Estimate], *,
         non_negative: bool = False) -> tuple[list[float], list[float]]:
    """The lower and upper edges of the 95 % CI band of ``estimates``: mean ∓ half-width (an
    undefined half-width, from one sample, counts as 0), the lower edge not below 0 for a metric
    declared never negative (:attr:`~searchtrack.sim.campaigns.experiments.Metric.non_negative`).
    """
    floor = 0.0 if non_negative else -math.inf
    half = [e.half_width if math.isfinite(e.half_width) else 0.0 for e in estimates]
    return ([max(floor, e.mean - h) for e, h in zip(estimates, half, strict=True)],
            [e.mean + h for e, h in zip(estimates, half, strict=True)])


def plot_metric(summaries: Sequence[GroupSummary], metric: str, path: Path, *,
                x_key: str, unit: str = "", title: str = "", non_negative: bool = False) -> Path:
    """``metric`` (mean with its 95 % CI band) against the parameter ``x_key``, one line per
    value of the other parameters; written atomically as PNG. The band of a metric that is
    ``non_negative`` is drawn from 0 up (:func:`band`)."""
    plt = pyplot()

    lines: dict[str, list[tuple[Any, Estimate]]] = {}
    for s in summaries:
        params = dict(s.params)
        rest = ", ".join(f"{k}={v}" for k, v in s.params if k != x_key) or metric
        lines.setdefault(rest, []).append((params.get(x_key), s.metrics[metric]))
    fig, ax = plt.subplots(figsize=(6.4, 4.0), dpi=DPI)
    for label, points in lines.items():
        points = [(x, e) for x, e in points if e.n > 0]
        if not points:
            continue
        numeric = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x, _ in points)
        points.sort(key=lambda p: p[0] if numeric else str(p[0]))
        xs = [x if numeric else str(x) for x, _ in points]
        ax.plot(xs, [e.mean for _, e in points], marker="o", label=label)
        ax.fill_between(xs, *band([e for _, e in points], non_negative=non_negative),
                        alpha=0.2)
        if numeric and all(isinstance(x, int) for x in xs):
            from matplotlib.ticker import MaxNLocator

            ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # no 3.5 UAVs
    ax.set_xlabel(x_key)
    ax.set_ylabel(f"{metric} ({unit})" if unit else metric)
    ax.set_title(title or f"{metric}: mean and 95 % CI")
    if len(lines) > 1:
        ax.legend(fontsize=7)
    return save_png(fig, path)


@dataclass(frozen=True)
class Report:
    """A campaign's report: what varies, the metrics (and those of them the experiment declares
    never negative), the grouped estimates and the claim."""

    name: str
    experiment: str
    group_keys: tuple[str, ...]
    metrics: tuple[str, ...]
    groups: tuple[GroupSummary, ...]
    claim: str | None
    non_negative: tuple[str, ...] = ()


def build_report(name: str, experiment: Experiment, metric_names: Sequence[str],
                 rows: Sequence[Row], missing: Sequence[Row] = ()) -> Report:
    """Group ``rows`` by the parameters of ``experiment`` that take more than one value (the
    grid keys) and estimate every numeric metric; the claim is the experiment's for these rows
    (:meth:`~searchtrack.sim.campaigns.experiments.Experiment.claim_for`). ``missing``: the
    parameters of the planned runs not run yet (:meth:`~searchtrack.sim.campaigns.store.
    ResultStore.missing`), counted in their groups."""
    varying = tuple(p.name for p in experiment.params
                    if len({_key(r.get(p.name)) for r in [*rows, *missing]}) > 1)
    numeric = tuple(m for m in metric_names
                    if any(isinstance(r.get(m), (int, float)) and not isinstance(r.get(m), bool)
                           for r in rows))
    return Report(name, experiment.name, varying, numeric,
                  tuple(summarise(rows, varying, numeric, missing)), experiment.claim_for(rows),
                  tuple(m for m in numeric if experiment.non_negative(m)))


def _key(value: Any) -> Any:
    return repr(value) if isinstance(value, float) and math.isnan(value) else value


def write_figures(report: Report, folder: Path) -> list[Path]:
    """One PNG per metric against the first varying parameter (numeric ones first), one line
    per value of the others, the bands of the metrics declared never negative from 0 up;
    nothing when no parameter varies."""
    if not report.group_keys or not report.groups:
        return []
    params = dict(report.groups[0].params)
    numeric = [k for k in report.group_keys
               if isinstance(params[k], (int, float)) and not isinstance(params[k], bool)]
    x_key = (numeric or list(report.group_keys))[0]
    return [plot_metric(report.groups, m, folder / f"{report.name}-{m}.png", x_key=x_key,
                        unit="s" if m.endswith("_s") else "",
                        title=f"{report.name}: {m} (mean, 95 % CI)",
                        non_negative=m in report.non_negative)
            for m in report.metrics]
