"""Closed-loop road tracking episodes (paper 000, §6)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.sim.road_particles.episode import (
    PAPER_GRID,
    GraphUAVs,
    RoadTrackingConfig,
    matched_error,
    run_road_tracking,
)

SMALL = {"histories": 3, "particles": 100, "duration_s": 30.0}


@pytest.fixture(scope="module")
def roads() -> DirectedRoads:
    return DirectedRoads(PAPER_GRID.build())


def test_an_episode_records_one_entry_per_scan(roads: DirectedRoads) -> None:
    config = RoadTrackingConfig(planner="random", **SMALL)
    log = run_road_tracking(config, 0, roads)
    assert log.times_s.shape == log.entropy.shape == log.error_m.shape == (30,)
    assert log.target_entropy.shape == (30, 2)
    assert np.allclose(np.diff(log.times_s), 1.0)
    assert np.all(log.entropy > 0) and np.all(np.isfinite(log.error_m))
    assert log.decisions >= 30 * 40 // 100 - 1  # a 100 m road every 2.5 s
    assert not log.interrupted


def test_the_same_seed_gives_the_same_episode(roads: DirectedRoads) -> None:
    config = RoadTrackingConfig(planner="exhaustive", **SMALL)
    a, b = run_road_tracking(config, 5, roads), run_road_tracking(config, 5, roads)
    assert np.array_equal(a.entropy, b.entropy) and np.array_equal(a.error_m, b.error_m)
    c = run_road_tracking(config, 6, roads)
    assert not np.array_equal(a.entropy, c.entropy)


def test_watching_the_targets_lowers_the_entropy(roads: DirectedRoads) -> None:
    """Over a few seeds the ideal planner (which knows where the targets are) ends with less
    entropy than the random one: finding the targets pays."""
    ideal, rand = [], []
    for seed in range(4):
        for planner, out in (("ideal", ideal), ("random", rand)):
            config = RoadTrackingConfig(planner=planner, histories=3, particles=200,
                                        duration_s=60.0)
            out.append(run_road_tracking(config, seed, roads).entropy[-20:].mean())
    assert np.mean(ideal) < np.mean(rand)


def test_a_stop_request_ends_the_episode_early(roads: DirectedRoads) -> None:
    request_stop()
    try:
        log = run_road_tracking(RoadTrackingConfig(planner="random", **SMALL), 0, roads)
    finally:
        clear_stop()
    assert log.interrupted and log.entropy.size == 0


def test_uavs_fly_along_roads_and_turn_at_nodes(roads: DirectedRoads) -> None:
    uavs = GraphUAVs.at_nodes(roads, np.array([4]), 40.0)
    asked: list[int] = []

    def choose(q: int, node: int) -> int:
        asked.append(node)
        return int(np.flatnonzero(roads.tail == node)[0])

    assert uavs.fly(0.0, choose) == 1  # at a node: chooses at once
    uavs.fly(3.0, choose)  # 120 m: past the next node, 20 m onto a new road
    assert len(asked) == 2 and asked[0] == 4
    assert uavs.s[0] == pytest.approx(20.0)
    with pytest.raises(ValueError, match="does not leave node"):
        uavs.fly(3.0, lambda q, node: int(np.flatnonzero(roads.tail != node)[0]))


def test_arrivals_are_the_next_node_and_the_time_to_it(roads: DirectedRoads) -> None:
    """A UAV 30 m into a 100 m road at 40 m/s reaches the road's head in 1.75 s."""
    uavs = GraphUAVs.at_nodes(roads, np.array([4, 0]), 40.0)
    road = int(roads.leaving(4)[0])
    uavs.edge[0], uavs.s[0] = road, 30.0
    nodes, left = uavs.arrivals()
    assert nodes.tolist() == [int(roads.head[road]), 0]
    assert left == pytest.approx([1.75, 0.0])


@pytest.mark.parametrize("coordination", ["joint", "alone"])
def test_two_uavs_fly_jointly_or_alone(roads: DirectedRoads, coordination: str) -> None:
    """Both ways run the episode through and are deterministic per seed."""
    config = RoadTrackingConfig(planner="exhaustive", uavs=2, coordination=coordination,  # type: ignore[arg-type]
                                **SMALL)
    a, b = (run_road_tracking(config, 5, roads) for _ in range(2))
    assert a.decisions > 0 and np.array_equal(a.entropy, b.entropy)


def test_matched_error_finds_the_best_matching() -> None:
    truth = np.array([[0.0, 0.0], [100.0, 0.0]])
    assert matched_error(truth[::-1], truth) == 0.0
    assert matched_error(truth + np.array([3.0, 4.0]), truth) == pytest.approx(5.0)
    many = np.arange(16.0).reshape(8, 2)
    assert matched_error(many[::-1], many) == 0.0


@pytest.mark.parametrize(("field", "value"), [
    ("targets", 0), ("uavs", 0), ("uav_speed_mps", -1.0), ("dt_s", float("nan")),
    ("truth_sigma_mps", -0.1), ("discount", 0.0), ("planner", "telepathy"),
    ("scan_period_s", 0.01), ("duration_s", 0.01), ("particles", 0),
    ("coordination", "telepathic")])
def test_bad_configs_name_the_field(field: str, value: object) -> None:
    with pytest.raises(InvalidInputError, match=field):
        RoadTrackingConfig(**{field: value})  # type: ignore[arg-type]


def test_the_jump_rate_reaches_the_filter() -> None:
    """0 (the paper's prior) gives no jumps; a positive rate gives the robust prior; a negative
    one is refused."""
    assert RoadTrackingConfig().filter_config().jumps is None
    jumps = RoadTrackingConfig(jump_rate_per_s=0.05).filter_config().jumps
    assert jumps is not None and jumps.rate_per_s == 0.05
    with pytest.raises(InvalidInputError):
        RoadTrackingConfig(jump_rate_per_s=-0.1)
