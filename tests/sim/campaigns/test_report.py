"""Campaign reports: grouped means with 95 % intervals, failed runs counted, figures drawn."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from searchtrack.sim.campaigns.experiments import Experiment, Metric, Param
from searchtrack.sim.campaigns.report import (
    band,
    build_report,
    plot_metric,
    summarise,
    table_rows,
    write_figures,
)
from searchtrack.sim.campaigns.stats import estimate

ROWS = [
    {"uavs": 3, "map": "a", "seed": 0, "status": "ok", "t": 10.0},
    {"uavs": 3, "map": "a", "seed": 1, "status": "ok", "t": 14.0},
    {"uavs": 3, "map": "a", "seed": 2, "status": "error", "t": None},
    {"uavs": 6, "map": "a", "seed": 0, "status": "ok", "t": 5.0},
    {"uavs": 6, "map": "a", "seed": 1, "status": "ok", "t": 7.0},
    {"uavs": 6, "map": "a", "seed": 2, "status": "ok", "t": math.nan},
]


def test_groups_estimate_only_their_ok_runs() -> None:
    """Each group's mean and t-interval use its ok, finite values; failures are counted."""
    groups = summarise(ROWS, ["uavs", "map"], ["t"])
    assert [g.label() for g in groups] == ["uavs=3, map=a", "uavs=6, map=a"]
    three, six = groups
    assert (three.runs, three.failed, six.failed) == (3, 1, 0)
    assert three.metrics["t"].mean == pytest.approx(12.0)
    # t(0.975, 1) = 12.706, s.d. = 2.828, n = 2: half-width 12.706 · 2.828 / √2 = 25.41
    assert three.metrics["t"].half_width == pytest.approx(25.4124, rel=1e-4)
    assert six.metrics["t"].n == 2 and six.metrics["t"].mean == pytest.approx(6.0)


def test_table_has_one_row_per_group() -> None:
    """The table starts with the parameters and runs, then one column per metric."""
    rows = table_rows(summarise(ROWS, ["uavs"], ["t"]), ["t"])
    assert rows[0] == ["uavs", "runs", "t"]
    assert rows[1][:2] == ["3", "3 (1 failed)"] and rows[1][2].startswith("12 ± ")


def test_figure_is_written_as_png(tmp_path: Path) -> None:
    """The metric against one parameter is drawn to a PNG and nothing else is left behind."""
    out = plot_metric(summarise(ROWS, ["uavs", "map"], ["t"]), "t", tmp_path / "t.png",
                      x_key="uavs", unit="s")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["t.png"]


def test_band_of_a_non_negative_metric_starts_at_zero() -> None:
    """Mean ∓ half-width, a single sample's undefined half-width as 0; the lower edge is cut
    at 0 only for a metric declared never negative."""
    wide, single = estimate([0.0, 2.0]), estimate([3.0])
    assert wide.mean - wide.half_width < 0.0
    low, high = band([wide, single])
    assert low == [wide.mean - wide.half_width, 3.0]
    assert high == [wide.mean + wide.half_width, 3.0]
    assert band([wide, single], non_negative=True) == ([0.0, 3.0], high)


def _signed_experiment() -> Experiment:
    return Experiment("signed", (Param("uavs", int, 1),),
                      {"d_m": Metric(float, non_negative=True), "x": Metric(float)},
                      lambda p, s: {"d_m": 0.0, "x": 0.0})


def test_figures_clip_only_the_bands_declared_non_negative(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The report reads the sign of each metric from the experiment's declaration: the band of
    the metric declared never negative stops at 0, that of the other goes below it."""
    from matplotlib.axes import Axes

    rows = [{"uavs": u, "seed": k, "status": "ok", "d_m": v, "x": v}
            for u in (1, 2) for k, v in enumerate((0.0, 2.0))]
    report = build_report("signed", _signed_experiment(), ["d_m", "x"], rows)
    assert report.metrics == ("d_m", "x") and report.non_negative == ("d_m",)
    lows: list[float] = []
    drawn = Axes.fill_between

    def record(self: Axes, x: object, y1: list[float], *args: object, **kw: object) -> object:
        lows.append(min(y1))
        return drawn(self, x, y1, *args, **kw)  # type: ignore[arg-type]

    monkeypatch.setattr(Axes, "fill_between", record)
    written = write_figures(report, tmp_path)
    assert [p.name for p in written] == ["signed-d_m.png", "signed-x.png"]
    assert lows[0] == 0.0 and lows[1] < 0.0


def test_report_groups_by_what_varies_and_finds_the_claim() -> None:
    """The groups are the parameters that take more than one value; the claim of a detect-mode
    mission campaign is the thesis's experiment 1 claim."""
    from searchtrack.sim.campaigns.experiments import ClaimsBy, get

    mission = get("mission")
    rows = [{**r, "mode": "detect", "targets": 8} for r in ROWS]
    report = build_report("exp1", mission, ["t"], rows)
    assert report.group_keys == ("uavs",) and report.metrics == ("t",)
    assert isinstance(mission.claim, ClaimsBy)
    assert report.claim == mission.claim.claims["detect"]
    assert report.claim.startswith("thesis §6.1, Fig. 6.3")
    assert [g.label() for g in report.groups] == ["uavs=3", "uavs=6"]


def test_every_experiments_claim_reaches_the_report() -> None:
    """For every registered experiment, a report of runs at its defaults carries its claim
    (for a claim per value of a parameter, the one of the value the runs share; none when they
    mix values); the paper experiments all state one."""
    from searchtrack.sim.campaigns.experiments import EXPERIMENTS, ClaimsBy

    stated = set()
    for exp in EXPERIMENTS.values():
        base = {**exp.resolve({}), "status": "ok", "seed": 0}
        if isinstance(exp.claim, ClaimsBy):
            for value, claim in exp.claim.claims.items():
                rows = [{**base, exp.claim.param: value}] * 2
                assert build_report("c", exp, list(exp.metrics), rows).claim == claim
            mixed = [{**base, exp.claim.param: v} for v in exp.claim.claims]
            assert build_report("c", exp, [], mixed).claim is None
        else:
            expected = exp.claim or None
            assert build_report("c", exp, list(exp.metrics), [base]).claim == expected
        if exp.claims():
            stated.add(exp.name)
    assert stated == {"mission", "phd_tracking_scenario", "phd_tracking_episode",
                      "phd_search_episode", "road_tracking_episode", "radio_tracking_episode"}
