"""The thesis's road experiments: each scenario builder sets what its experiment varies, and a
short run is scored as the benchmark tables report it."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.models.lrt_sensor import THESIS_ALTITUDES_M, AltitudeModel
from searchtrack.sim.roads.experiment import (
    DETECTION_SENSOR,
    MAPS,
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
