"""Mission records: phase timings, the recorder's frozen log, its scores and its JSON form."""

from __future__ import annotations

import json

import numpy as np
import pytest

from searchtrack.estimate import LikelihoodField, TrackerBank
from searchtrack.models import grid_network
from searchtrack.sim.roads.record import PHASES, Recorder, StepTimes
from tests.sim.roads.mission_logs import LLR, SCENARIO, empty_log, tracker_probability, two_step_log


def test_step_times_are_milliseconds_in_phase_order() -> None:
    """as_ms lists each phase's seconds × 1000 in PHASES order."""
    times = StepTimes(truth=0.001, sense=0.002, associate=0.003, update=0.004, initiate=0.005,
                      guide=0.006, predict=0.007)
    assert PHASES == ("truth", "sense", "associate", "update", "initiate", "guide", "predict")
    assert times.as_ms() == pytest.approx([1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0])
    assert StepTimes().as_ms() == [0.0] * 7


def test_recorder_keeps_every_step() -> None:
    """Paths start with the start positions; steps, modes, plans, tracks, pairs and births are
    kept in order; the final trackers are the bank's summed distributions."""
    log = two_step_log()
    np.testing.assert_array_equal(log.time_s, [0.3, 0.6])
    assert log.uav_xy_m.shape == (3, 2, 2) and log.target_xy_m.shape == (3, 2, 2)
    np.testing.assert_array_equal(log.uav_xy_m[0], [[0.0, 0.0], [100.0, 100.0]])
    np.testing.assert_array_equal(log.target_xy_m[2], [[60.0, 0.0], [0.0, 40.0]])
    assert log.modes == (("search", "loiter"), ("search", "search"))
    np.testing.assert_array_equal(log.plan_ms, [2.5, 0.0])
    assert log.tracks == (((0, 3, 0.7),), ((0, 3, 0.7),))
    assert log.associations == (((0, 0, 1),), ((1, 0, -1),))
    assert [(b.time_s, b.track_id, b.target, b.distance_m) for b in log.births] == [
        (0.3, 0, 1, 12.345)]
    np.testing.assert_array_equal(log.final_llr, LLR)
    np.testing.assert_allclose(log.final_trackers, tracker_probability())


def test_scores_moc_and_step_time() -> None:
    """MOC is valid trackers / targets per step; PVT = PVA = 1/2; the filter-and-plan time is
    every phase but truth and sense (3 + 4 + 5 + 6 + 7 = 25 ms)."""
    log = two_step_log()
    s = log.score
    assert (s.steps, s.targets, s.nvt, s.nst, s.nva, s.nfa) == (2, 2, 1, 1, 1, 1)
    assert (s.pvt, s.pva, s.detected, s.time_to_detect_all_s) == (0.5, 0.5, 1, None)
    assert (s.moc_mean, s.moc_final) == (0.25, 0.0)
    np.testing.assert_array_equal(log.moc, [0.5, 0.0])
    np.testing.assert_allclose(log.phase_ms, [[1, 2, 3, 4, 5, 6, 7], [0] * 7])
    np.testing.assert_allclose(log.step_ms, [25.0, 0.0])


def test_json_is_plain_and_rounded() -> None:
    """to_json survives json.dumps; it rounds distances to 0.1 m, and never-detected targets
    are null."""
    d = json.loads(json.dumps(two_step_log().to_json()))
    assert d["scenario"]["map"] == "grid 2x2 @ 100 m"
    assert (d["scenario"]["uavs"], d["scenario"]["targets"], d["scenario"]["seed"]) == (2, 2, 7)
    assert d["scenario"]["sensor"]["footprint_radius_m"] == 150.0
    assert d["network"] == {"nodes": 8, "edges": 8, "intersections": 0}
    summary = d["summary"]
    assert (summary["moc_mean"], summary["pvt"], summary["nfa"]) == (0.25, 0.5, 1)
    assert summary["step_ms_median"] == pytest.approx(12.5)
    assert summary["step_ms_p95"] == pytest.approx(23.75)
    assert summary["phase_ms_mean"]["guide"] == pytest.approx(3.0)
    assert d["first_detection_s"] == [0.3, None]
    assert d["births"] == [{"time_s": 0.3, "track_id": 0, "target": 1, "distance_m": 12.3}]
    assert d["tracks"] == [[[0, 3, 0.7]], [[0, 3, 0.7]]]
    assert d["associations"] == [[[0, 0, 1]], [[1, 0, -1]]]
    assert (d["trackers"], d["valid_trackers"], d["false_associations"]) == ([1, 1], [1, 0],
                                                                              [0, 1])
    assert d["moc"] == [0.5, 0.0] and d["modes"][0] == ["search", "loiter"]
    assert d["uav_xy_m"][2][0] == [20.0, 0.0]


def test_a_log_without_steps() -> None:
    """With no step the log holds the start positions only, no trackers, and no step timings."""
    log = empty_log()
    assert log.time_s.size == 0 and log.uav_xy_m.shape == (1, 2, 2)
    assert log.phase_ms.shape == (0, len(PHASES)) and log.step_ms.size == 0
    np.testing.assert_array_equal(log.final_trackers, np.zeros(8))
    summary = log.to_json()["summary"]
    assert summary["steps"] == 0 and summary["step_ms_median"] is None
    assert summary["phase_ms_mean"] == {}


def test_handover_births_are_flagged() -> None:
    """A birth handed over to a live tracker is kept with ``handover`` set and says so in the
    JSON; other births' JSON is unchanged. The summary reports MOC after detection (``None``
    for hand-made steps that list no tracked target)."""
    net = grid_network(2, 2, 100.0, 50.0)
    rec = Recorder(SCENARIO, net, np.zeros((2, 2)), np.zeros((2, 2)))
    rec.birth(0.3, 0, 1, 5.0)
    rec.birth(0.6, 0, 1, 7.0, handover=True)
    log = rec.finish(LikelihoodField(LLR), TrackerBank(net.n_nodes), np.array([0.3, np.nan]))
    assert [b.handover for b in log.births] == [False, True]
    births = log.to_json()["births"]
    assert "handover" not in births[0] and births[1]["handover"] is True
    assert two_step_log().to_json()["summary"]["moc_after_detection"] is None
