"""Paper 002's Experiment 2 as a campaign experiment."""

from __future__ import annotations

import json

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.radio import RadioScenario, RadioSignal, UavModel
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.sim.campaigns.experiments import get
from searchtrack.sim.radio.config import RadioMissionConfig
from searchtrack.sim.radio.experiment import EXPERIMENTS, METRICS, PARAMS, radio_episode


def test_registered_with_its_parameters_and_metrics() -> None:
    exp = get("radio_tracking_episode")
    assert (exp,) == EXPERIMENTS and exp.run is radio_episode
    assert exp.params == PARAMS
    assert [p.name for p in exp.params] == [
        "filter", "planner", "noise_std_v", "particles", "plan_particles", "horizon", "headings",
        "backend", "measurement", "keep_out", "temper_correlated", "roughening_m",
        "replan_on_breach", "p_void_min",
        "spread_inflation", "explore_existence", "calibration_gain_db", "front_to_back_db",
        "duration_s"]
    assert dict(exp.metrics) == METRICS
    assert exp.claims()[0].startswith("paper 002, Fig. 8:")
    with pytest.raises(InvalidInputError, match="planner"):
        exp.resolve({"planner": "zigzag"})
    with pytest.raises(InvalidInputError, match="noise_std_v"):
        exp.resolve({"noise_std_v": "loud"})


def test_defaults_are_the_settings() -> None:
    """The parameters that set a mission, planner, UAV or scenario field take its default."""
    exp = get("radio_tracking_episode")
    sources = {"filter": RadioMissionConfig.filter, "planner": RadioMissionConfig.planner,
               "backend": RadioMissionConfig.backend,
               "measurement": RadioMissionConfig.measurement,
               "keep_out": RadioMissionConfig.keep_out, "horizon": RadioPlanSettings.horizon,
               "replan_on_breach": RadioMissionConfig.replan_on_breach,
               "temper_correlated": RadioMissionConfig.temper_correlated,
               "roughening_m": RadioMissionConfig.roughening_m,
               "p_void_min": RadioPlanSettings.p_void_min, "headings": UavModel.n_headings,
               "spread_inflation": RadioPlanSettings.spread_inflation,
               "explore_existence": RadioPlanSettings.explore_existence,
               "calibration_gain_db": RadioSignal.calibration_gain_db,
               "front_to_back_db": RadioSignal.front_to_back_db,
               "duration_s": RadioScenario.duration_s}
    for name, default in sources.items():
        assert exp.param(name).default == default, name


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
    assert 0.0 <= float(metrics["cardinality_hit_fraction"]) <= 1.0  # type: ignore[arg-type]
    assert 0 <= int(metrics["objects_detected"]) <= 1  # type: ignore[call-overload]  # one born
