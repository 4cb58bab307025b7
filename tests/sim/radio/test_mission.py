"""The closed loop of paper 002: flown, scored, deterministic, interruptible."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.estimate.labelled_particles import LabelledParticles
from searchtrack.models.radio import RadioScenario
from searchtrack.plan.radio import RadioPlanSettings
from searchtrack.sim.radio.mission import RadioMissionConfig, _Flight, run_radio_mission


@pytest.fixture(scope="module")
def scenario() -> RadioScenario:
    return dataclasses.replace(RadioScenario.paper(noise_var_v2=0.015**2), duration_s=12.0)


def _config(**changes: object) -> RadioMissionConfig:
    plan = RadioPlanSettings(horizon=2, plan_particles=40)
    return RadioMissionConfig(**{"particles_per_label": 150, "plan": plan, **changes})


@pytest.mark.parametrize(("filt", "planner"), [("tbd", "renyi"), ("dtt", "cs"),
                                                ("tbd", "straight")])
def test_a_run_is_scored_every_second(scenario: RadioScenario, filt: str,
                                      planner: str) -> None:
    log = run_radio_mission(scenario, _config(filter=filt, planner=planner), 2)
    k = scenario.n_steps
    assert log.steps == k and log.poses.shape == (k + 1, 3) and log.ospa.shape == (k, 3)
    assert np.all((log.ospa >= 0) & (log.ospa <= 100.0 + 1e-9))
    assert np.allclose(log.ospa[:, 0], log.ospa[:, 1] + log.ospa[:, 2])   # p = 1
    steps = np.hypot(*np.diff(log.poses[:, :2], axis=0).T)
    assert np.allclose(steps, scenario.uav.speed_mps, atol=1e-6)
    assert 0.0 <= log.unsafe_fraction() <= 1.0
    assert log.existence.shape == (k, scenario.signal.n_labels)
    if planner == "straight":
        assert log.planner_ms == [] and log.plan_status == {"straight": 3}
    else:
        assert len(log.planner_ms) == 3 and sum(log.plan_status.values()) == 3
        assert log.config.plan.reward == planner
    doc = log.to_json()
    assert doc["steps"] == k and len(doc["ospa"]) == k


def test_deterministic_for_a_seed(scenario: RadioScenario) -> None:
    a = run_radio_mission(scenario, _config(), 7)
    b = run_radio_mission(scenario, _config(), 7)
    assert np.array_equal(a.poses, b.poses) and np.array_equal(a.ospa, b.ospa)


def test_a_stop_keeps_what_was_flown(scenario: RadioScenario) -> None:
    def stop(done: int, _n: int) -> None:
        if done == 4:
            request_stop()

    try:
        log = run_radio_mission(scenario, _config(planner="straight"), 1, stop)
    finally:
        clear_stop()
    assert log.interrupted and log.steps == 4 and log.poses.shape == (5, 3)


@pytest.mark.parametrize(("field", "value"), [("filter", "kalman"), ("planner", "random"),
                                              ("measurement", "radar"),
                                              ("particles_per_label", 0),
                                              ("plan_time_limit_s", -1.0),
                                              ("keep_out", "yes"), ("replan_on_breach", 1),
                                              ("ospa_c_m", 0.0)])
def test_bad_configuration_is_named(field: str, value: object) -> None:
    with pytest.raises(InvalidInputError, match=field):
        RadioMissionConfig(**{field: value})


def test_bad_seed(scenario: RadioScenario) -> None:
    with pytest.raises(InvalidInputError, match="seed"):
        run_radio_mission(scenario, _config(), -3)


def test_keep_out_flies_the_primitives_through_the_controller(scenario: RadioScenario) -> None:
    plain = run_radio_mission(scenario, _config(planner="cs"), 5)
    kept = run_radio_mission(scenario, _config(planner="cs", keep_out=True), 5)
    steps = np.hypot(*np.diff(kept.poses[:, :2], axis=0).T)
    assert kept.steps == scenario.n_steps and kept.config.keep_out
    assert np.all((steps > 0.9 * scenario.uav.speed_mps) & (steps <= scenario.uav.speed_mps
                                                              + 1e-6))
    assert not np.array_equal(kept.poses, plain.poses)     # arcs, not the primitive's chords
    assert kept.to_json()["summary"]["keep_out_fallbacks"] == kept.keep_out_fallbacks


def test_fig5_scores_follow_their_definitions(scenario: RadioScenario) -> None:
    """The cardinality hit fraction and the objects detected, recomputed from the log."""
    log = run_radio_mission(scenario, _config(), 3)
    alive = np.array([log.truth.positions(k)[0].size for k in range(log.steps)])
    hit = np.mean(np.abs(log.cardinality_mean - alive) <= 0.5)
    assert log.cardinality_hit_fraction() == pytest.approx(hit)
    assert log.cardinality_hit_fraction(tolerance=10.0) == 1.0
    seen = set()
    for k, row in enumerate(log.estimates):
        labels, xy = log.truth.positions(k)
        for lab, p in row:
            if lab in labels.tolist():
                i = labels.tolist().index(lab)
                if np.hypot(*(xy[i] - np.array(p))) < 100.0:
                    seen.add(lab)
    assert log.objects_detected() == len(seen)
    summary = log.to_json()["summary"]
    assert summary["objects_detected"] == len(seen) and summary["breach_replans"] == 0


def test_a_breach_ahead_drops_the_rest_of_the_path() -> None:
    """replan_on_breach: an object the belief puts on the path ahead empties the path (the next
    second plans again) and is counted; off the path, or without the option, nothing changes."""
    sc = RadioScenario.paper()
    rng = np.random.default_rng(0)
    x = np.zeros((4, 100, 4))
    x[:, :, 0], x[:, :, 2] = 1400.0, 1400.0                 # every label far away ...
    x[0, :, 0] = 300.0 + rng.normal(0.0, 5.0, 100)          # ... but label 0 on the path
    x[0, :, 2] = 200.0 + rng.normal(0.0, 5.0, 100)
    state = LabelledParticles(x, np.zeros((4, 100), dtype=np.int8), np.full((4, 100), 0.2),
                              np.full((4, 100), 0.01), np.array([0.99, 0.5, 0.5, 0.5]))
    belief = SimpleNamespace(state=state)
    path = np.array([[100.0 * i, 200.0, 0.0] for i in range(1, 5)])
    for replan, y, dropped in ((True, 200.0, True), (True, 600.0, False), (False, 200.0, False)):
        flight = _Flight(sc, _config(replan_on_breach=replan), 0)
        flight.path = path + np.array([0.0, y - 200.0, 0.0])
        flight.check_breach(belief)  # type: ignore[arg-type]
        assert (flight.path.shape[0] == 0) == dropped
        assert flight.breach_replans == int(dropped)
