"""Closed-loop missions: a short seeded mission is deterministic, finds targets, and stops once
all are detected in detect mode."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.estimate.association import BACKENDS as ASSOCIATION_BACKENDS
from searchtrack.models import SensorModel
from searchtrack.sim.roads.mission import Mission, World
from searchtrack.sim.roads.scenario import GuidanceSpec, MapSpec, Scenario

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)


def small(strategy: str = "search_and_loiter", **changes: object) -> Scenario:
    """A 6 × 6 grid of 100 m blocks, 2 UAVs, 2 targets, 30 s."""
    base = Scenario("small", MapSpec("grid", rows=6, cols=6, block_m=100.0), uav_count=2,
                    target_count=2, sensor=SENSOR, altitude_m=None, duration_s=30.0, seed=3,
                    guidance=GuidanceSpec(strategy=strategy))
    return dataclasses.replace(base, **changes)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def world() -> World:
    """The grid and its operators, built once."""
    return World.build(small())


def test_same_seed_same_mission(world: World) -> None:
    """Two runs with one seed agree exactly; another seed differs."""
    a = Mission(small(), world).run()
    b = Mission(small(), world).run()
    c = Mission(small(seed=4), world).run()
    np.testing.assert_array_equal(a.uav_xy_m, b.uav_xy_m)
    np.testing.assert_array_equal(a.final_llr, b.final_llr)
    assert a.score == b.score
    assert not np.array_equal(a.uav_xy_m, c.uav_xy_m)


@pytest.mark.parametrize("strategy", ["loiter", "search_and_loiter", "search_and_reacquire"])
def test_tracking_strategies_find_targets(world: World, strategy: str) -> None:
    """On a small map every tracking strategy detects a target within a minute, with valid
    trackers most of the time once it has one."""
    log = Mission(small(strategy, duration_s=60.0), world).run()
    assert log.score.detected >= 1
    assert log.score.pvt is not None and log.score.pvt > 0.5
    assert len(log.time_s) == log.scenario.n_steps
    assert log.uav_xy_m.shape == (log.scenario.n_steps + 1, 2, 2)
    assert [len(t) for t in log.tracks] == [st.trackers for st in log.steps]
    assert sum(len(a) for a in log.associations) == log.score.nva + log.score.nfa
    live = {tid for step in log.tracks for tid, _, _ in step}
    assert {tid for step in log.associations for _, tid, _ in step} <= live | {
        b.track_id for b in log.births}


@pytest.mark.parametrize("strategy", ["route_loiter", "route_search_and_reacquire",
                                      "route_partition_loiter"])
def test_route_strategies_fly_search_routes(world: World, strategy: str) -> None:
    """A short mission with a route strategy runs through, its searching UAVs flying planned
    search routes, and repeats exactly for its seed (its reacquisition OPTW capped in
    iterations, so that a busy machine flies the same routes)."""
    spec = GuidanceSpec(strategy=strategy, optw_backend="ils", optw_iterations=300,
                        optw_budget_s=5.0)
    a = Mission(small(guidance=spec), world).run()
    b = Mission(small(guidance=spec), world).run()
    assert len(a.time_s) == a.scenario.n_steps
    assert any("route" in modes for modes in a.modes)
    np.testing.assert_array_equal(a.uav_xy_m, b.uav_xy_m)
    assert a.score == b.score and a.modes == b.modes


@pytest.mark.parametrize("associator", ASSOCIATION_BACKENDS.names())
def test_every_associator_flies(world: World, associator: str) -> None:
    """The mission builds its associator by backend name; each one associates fixes."""
    sc = small(filter=dataclasses.replace(small().filter, associator=associator))
    mission = Mission(sc, world)
    lrt_filter = mission.new_filter()
    assert lrt_filter.associator.inner.backend == associator  # type: ignore[attr-defined]
    log = mission.run()
    assert log.score.detected >= 1
    assert sum(len(a) for a in log.associations) == log.score.nva + log.score.nfa > 0


def test_detect_mode_stops_when_all_found(world: World) -> None:
    """Detection-only search ends once every target is found, and each is found once."""
    log = Mission(small("search", mode="detect", duration_s=600.0), world).run()
    assert log.score.detected == 2
    assert log.score.time_to_detect_all_s is not None
    assert log.time_s[-1] == pytest.approx(log.score.time_to_detect_all_s)
    assert sorted(b.target for b in log.births if b.target >= 0) == [0, 1]


def rbpf(strategy: str, **changes: object) -> Scenario:
    """:func:`small` estimated with a small RBPF (3 histories × 100 particles)."""
    sc = small(strategy, **changes)
    return dataclasses.replace(sc, filter=dataclasses.replace(sc.filter, belief="rbpf",
                                                              histories=3, particles=100))


@pytest.mark.parametrize("strategy", ["search", "loiter", "search_and_loiter",
                                      "search_and_reacquire"])
def test_every_strategy_flies_on_the_rbpf(world: World, strategy: str) -> None:
    """With ``belief = "rbpf"`` every guidance strategy flies the mission on the RBPF's bank and
    search field, and the log is whole: a step per step, tracks as counted, associations as
    scored, tracks born before they associate; the final field is finite."""
    log = Mission(rbpf(strategy), world).run()
    n = log.scenario.n_steps
    assert len(log.time_s) == n and log.uav_xy_m.shape == (n + 1, 2, 2)
    assert [len(t) for t in log.tracks] == [st.trackers for st in log.steps]
    assert sum(len(a) for a in log.associations) == log.score.nva + log.score.nfa
    assert {tid for step in log.associations for _, tid, _ in step} <= {
        b.track_id for b in log.births}
    assert all(0 <= tid < 2 for step in log.tracks for tid, _, _ in step)
    assert np.all(np.isfinite(log.final_llr))
    assert log.score.detected >= 1


def test_rbpf_mission_is_deterministic(world: World) -> None:
    """Two RBPF missions with one seed agree exactly."""
    a = Mission(rbpf("search_and_loiter", duration_s=9.0), world).run()
    b = Mission(rbpf("search_and_loiter", duration_s=9.0), world).run()
    np.testing.assert_array_equal(a.uav_xy_m, b.uav_xy_m)
    np.testing.assert_array_equal(a.final_llr, b.final_llr)
    assert a.score == b.score
