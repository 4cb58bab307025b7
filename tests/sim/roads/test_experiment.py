"""The thesis's road experiments: each scenario builder sets what its experiment varies, and a
short run is scored as the benchmark tables report it; the campaign's ``mission`` experiment."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.models.lrt_sensor import THESIS_ALTITUDES_M, AltitudeModel
from searchtrack.sim.campaigns.experiments import ClaimsBy, get
from searchtrack.sim.campaigns.spec import read_spec
from searchtrack.sim.roads.experiment import (
    DETECTION_SENSOR,
    EXPERIMENTS,
    MAPS,
    MISSION_MAPS,
    TRACKING_STRATEGIES,
    detection_scenario,
    detection_time_s,
    step_samples,
    step_scenario,
    tracking_base,
    tracking_run,
    tracking_scenario,
    with_fleet,
    with_strategy,
)
from searchtrack.sim.roads.record import PHASES
from searchtrack.sim.roads.scenario import MODES, FilterSpec, GuidanceSpec, Scenario
from searchtrack.sim.roads.seeds import fly_seeds


def test_detection_scenario_is_table_6_2() -> None:
    """Experiment 1: 8 targets, search in detect mode, 50 °/s turns, the fleet set apart."""
    sc = with_fleet(detection_scenario("grid-dense", max_duration_s=60.0, llr_floor=-5.0), 4)
    assert sc.map == MAPS["grid-dense"] and sc.mode == "detect" and sc.uav_count == 4
    assert sc.target_count == 8 and sc.sensor == DETECTION_SENSOR and sc.duration_s == 60.0
    assert sc.limits.turn_rate_max_rps == pytest.approx(math.radians(50.0))
    assert sc.guidance.strategy == "search" and sc.filter.llr_floor == -5.0


@pytest.mark.parametrize("altitude_m", THESIS_ALTITUDES_M)
def test_tracking_scenario_takes_the_altitude_models_sensor(altitude_m: float) -> None:
    """Experiment 2: fleet, targets, strategy and the sensor of (6.4)–(6.7) at the altitude."""
    sc = tracking_scenario(tracking_base("grid-dense", duration_s=30.0), uavs=3, targets=2,
                           altitude_m=altitude_m, strategy="loiter")
    assert (sc.uav_count, sc.target_count, sc.altitude_m) == (3, 2, altitude_m)
    assert sc.sensor == AltitudeModel().sensor(altitude_m) and sc.guidance.strategy == "loiter"
    assert sc.mode == "track" and sc.duration_s == 30.0
    assert set(TRACKING_STRATEGIES) == {"loiter", "search_and_loiter", "search_and_reacquire"}


def test_runs_are_scored_from_their_logs() -> None:
    """A short tracking run's scores are the log's MOC, PVT, PVA and planning time; the step
    samples line up with the steps flown."""
    base = tracking_base("grid-dense", duration_s=20.0)
    sc = tracking_scenario(base, uavs=1, targets=2, altitude_m=1828.8,
                           strategy="search_and_loiter")
    (log,) = fly_seeds(sc, [0])
    run = tracking_run(log)
    assert run.moc_mean == log.score.moc_mean
    assert run.moc_last_third == pytest.approx(float(log.moc[2 * len(log.moc) // 3:].mean()))
    assert run.pvt_pct == (None if log.score.pvt is None else 100 * log.score.pvt)
    assert run.plan_ms_p95 == pytest.approx(float(np.percentile(log.plan_ms, 95)))
    assert detection_time_s(log) == log.score.time_to_detect_all_s
    counts, ms, phases = step_samples([log, log])
    assert counts.shape == ms.shape == (2 * log.score.steps,)
    assert phases.shape == (2 * log.score.steps, len(PHASES))


def test_step_scenario_is_three_uavs_at_the_highest_altitude() -> None:
    """The step budget: Aguascalientes, 3 UAVs, 4 targets, 1828.8 m; the strategy set apart."""
    sc = with_strategy(step_scenario(duration_s=10.0), "search_and_reacquire")
    assert sc.map == MAPS["aguascalientes"] and (sc.uav_count, sc.target_count) == (3, 4)
    assert sc.altitude_m == max(THESIS_ALTITUDES_M) and sc.duration_s == 10.0
    assert sc.guidance.strategy == "search_and_reacquire"


def _run(params: dict[str, object], seed: int = 1) -> dict[str, object]:
    exp = get("mission")
    metrics = exp.run(exp.resolve(params), seed)
    assert set(metrics) == set(exp.metrics)
    return dict(metrics)


def test_mission_is_declared_with_a_claim_per_mode() -> None:
    """The registered ``mission`` is this module's, with experiment 1's claim in detect mode
    and experiment 2's in track mode."""
    (exp,) = EXPERIMENTS
    assert get("mission") is exp
    assert isinstance(exp.claim, ClaimsBy) and exp.claim.param == "mode"
    assert set(exp.claim.claims) == set(MODES)
    assert exp.claim_for([{"mode": "detect"}]).startswith("thesis §6.1")  # type: ignore[union-attr]
    assert exp.claim_for([{"mode": "track"}]).startswith("thesis §6.2")  # type: ignore[union-attr]
    assert exp.param("map").choices == tuple(MISSION_MAPS)


def test_mission_defaults_are_the_scenarios() -> None:
    """Each parameter that sets a scenario, filter or guidance field takes its default."""
    exp = get("mission")
    sources = {"mode": Scenario.mode, "uavs": Scenario.uav_count,
               "targets": Scenario.target_count, "altitude_m": Scenario.altitude_m,
               "duration_s": Scenario.duration_s, "strategy": GuidanceSpec.strategy,
               "coverage_weight": GuidanceSpec.coverage_weight, "handover": FilterSpec.handover}
    for name, default in sources.items():
        assert exp.param(name).default == default, name


@pytest.mark.parametrize("mode", ["track", "detect"])
def test_mission_runs_on_the_small_grid(mode: str) -> None:
    """A short mission on the small grid returns its detections and scores."""
    metrics = _run({"mode": mode, "duration_s": 5.0, "uavs": 2, "targets": 2})
    assert 0 <= int(metrics["detected"]) <= 2  # type: ignore[call-overload]
    assert 0.0 <= float(metrics["moc_mean"]) <= 1.0  # type: ignore[arg-type]


def test_mission_options_defaults_and_checks(tmp_path: Path) -> None:
    """``tracker_alpha`` and ``coverage_weight`` default to off (0), ``handover`` to on;
    a negative value is refused naming the parameter, in Python and in a campaign file (the
    file and the dotted key)."""
    mission = get("mission")
    resolved = mission.resolve({})
    assert (resolved["tracker_alpha"], resolved["handover"], resolved["coverage_weight"]) == (
        0.0, True, 0.0)
    assert "moc_after_detection" in mission.metrics
    for name, bad in [("tracker_alpha", -0.5), ("coverage_weight", -1.0),
                      ("tracker_alpha", float("inf")), ("handover", 1)]:
        with pytest.raises(InvalidInputError) as info:
            mission.resolve({name: bad})
        assert info.value.field == name
    path = tmp_path / "bad.toml"
    path.write_text('name = "b"\nexperiment = "mission"\nseeds = [0]\n[grid]\n'
                    'cells = [{uavs = 1, tracker_alpha = -1.0}]\n', encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert err.value.field == "grid.cells[0].tracker_alpha" and "bad.toml" in str(err.value)
    path.write_text('name = "b"\nexperiment = "mission"\nseeds = [0]\n[settings]\n'
                    'coverage_weight = -2.0\n[grid]\nuavs = [1]\n', encoding="utf-8")
    with pytest.raises(ParseError) as err:
        read_spec(path)
    assert err.value.field == "settings.coverage_weight"


def test_mission_options_reach_the_scenario() -> None:
    """Switched on, the options change a short grid mission's run; off, the run is the one the
    scenario without them flies; MOC after detection is reported."""
    common: dict[str, object] = {"duration_s": 20.0, "uavs": 2, "targets": 2}
    base = _run(common, seed=7)
    assert base == _run({**common, "tracker_alpha": 0.0, "handover": False,
                         "coverage_weight": 0.0, "steering": "turn_back"}, seed=7)
    after = base["moc_after_detection"]
    assert after is None or 0.0 <= float(after) <= 1.0  # type: ignore[arg-type]
    for option in ({"tracker_alpha": 4.47}, {"coverage_weight": 2.0}, {"steering": "thesis"}):
        assert _run({**common, **option}, seed=7) != base, option
