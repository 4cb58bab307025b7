"""Paper 002's Experiment 2 as a campaign experiment."""

from __future__ import annotations

import json

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.radio.experiment import METRICS, PARAMS, radio_episode


def test_registered_with_its_parameters_and_metrics() -> None:
    exp = get("radio_tracking_episode")
    assert [p.name for p in exp.params] == list(PARAMS)
    assert dict(exp.metrics) == METRICS
    with pytest.raises(InvalidInputError, match="planner"):
        exp.resolve({"planner": "zigzag"})
    with pytest.raises(InvalidInputError, match="noise_std_v"):
        exp.resolve({"noise_std_v": "loud"})


@pytest.mark.parametrize("planner", ["straight", "cs"])
def test_one_short_run(planner: str) -> None:
    params = get("radio_tracking_episode").resolve({
        "planner": planner, "duration_s": 6.0, "particles": 80, "plan_particles": 20,
        "horizon": 1, "headings": 4, "noise_std_v": 0.02})
    metrics = radio_episode(params, 3)
    assert set(metrics) == set(METRICS)
    series = json.loads(str(metrics["ospa_series"]))
    assert len(series) == 6
    assert metrics["mean_ospa_m"] == pytest.approx(sum(series) / 6, abs=0.01)
    assert 0.0 <= float(metrics["unsafe_fraction"]) <= 1.0  # type: ignore[arg-type]
    assert (metrics["planner_ms"] is None) == (planner == "straight")
