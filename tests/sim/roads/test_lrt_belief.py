"""The thesis's LRT field and node trackers stepped as one road filter: a target under a UAV
raises the field, is born as a tracker and then takes the fixes; detect mode drops trackers at
birth; the operators come from the scenario."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.association import Association
from searchtrack.estimate.stepping import RoadFilter, RoadScan, TrackBirth, TrackPair
from searchtrack.models import SensorModel, UavState, lrt_measurements, position_measurements
from searchtrack.sim.roads.lrt_belief import LRTMissionBelief, TimedAssociator
from searchtrack.sim.roads.metrics import credit_birth
from searchtrack.sim.roads.scenario import FilterSpec, MapSpec, Scenario
from searchtrack.sim.roads.world import World

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)
SCENARIO = Scenario("lrt", MapSpec("grid", rows=4, cols=4, block_m=100.0), uav_count=1,
                    target_count=1, sensor=SENSOR, altitude_m=None, seed=2,
                    filter=FilterSpec(handover=False))
UAV = UavState(np.array([150.0]), np.array([110.0]), np.zeros(1), np.full(1, 30.0))


@pytest.fixture(scope="module")
def world() -> World:
    """The 4 × 4 grid and its diffusions."""
    return World.build(SCENARIO)


def _fly(belief: LRTMissionBelief, world: World, steps: int,
         seed: int = 0) -> tuple[list[TrackPair], list[TrackBirth], np.ndarray]:
    """``steps`` scans of a target standing on the node nearest (150, 100), each followed by a
    prediction; the pairs, the births and each measurement's true target."""
    net = world.network
    node = net.nearest_nodes(np.array([[150.0, 100.0]]))
    rng = np.random.default_rng(seed)
    pairs: list[TrackPair] = []
    births: list[TrackBirth] = []
    truth: list[int] = []
    for k in range(steps):
        lrt = lrt_measurements(net, UAV.xy_m, node, SENSOR, rng)
        pos = position_measurements(UAV.xy_m, net.coords[node], SENSOR, rng)
        found = belief.update(RoadScan(SCENARIO.dt_s * (k + 1), pos, lrt), UAV)
        pairs += found.pairs
        births += found.births
        truth += [int(pos.target[q]) for _, _, q in found.pairs]
        belief.predict(SCENARIO.dt_s)
    return pairs, births, np.array(truth)


def test_a_target_under_a_uav_is_born_and_tracked(world: World) -> None:
    """The field rises under the target until a tracker is born there (credited to it); the
    later fixes go to that tracker (pairs name the measurement rows, of the true target); the
    filter is a RoadFilter whose estimates are its trackers' peaks."""
    belief = LRTMissionBelief.for_mission(SCENARIO, world, np.random.default_rng(0))
    assert isinstance(belief, RoadFilter)
    assert belief.estimates_xy().shape == (0, 2)
    pairs, births, truth = _fly(belief, world, 12)
    target_xy = world.network.coords[world.network.nearest_nodes(np.array([[150.0, 100.0]]))]
    assert [b.track_id for b in births] == [0] and not births[0].handover
    assert credit_birth(births[0].xy_m, target_xy, SCENARIO.valid_distance_m)[0] == 0
    assert len(belief.bank) == 1
    assert np.linalg.norm(belief.estimates_xy()[0] - target_xy[0]) < SCENARIO.valid_distance_m
    assert pairs and {track for _, track, _ in pairs} == {0}
    assert {uav for uav, _, _ in pairs} == {0} and np.all(truth == 0)
    assert belief.search_field is belief.field


def test_detect_mode_drops_each_tracker_at_birth(world: World) -> None:
    """In detect mode the birth is reported and the tracker dropped: the bank stays empty."""
    sc = dataclasses.replace(SCENARIO, mode="detect")
    belief = LRTMissionBelief.for_mission(sc, world, np.random.default_rng(0))
    _, births, _ = _fly(belief, world, 12)
    assert len(births) >= 1 and len(belief.bank) == 0


def test_operators_follow_the_scenario(world: World) -> None:
    """The associator is the scenario's backend, timed; the predictions are the world's
    diffusions; hand-over follows ``filter.handover``."""
    sc = dataclasses.replace(SCENARIO, filter=FilterSpec(associator="optimal", handover=True))
    belief = LRTMissionBelief.for_mission(sc, world, np.random.default_rng(0))
    assert isinstance(belief.associator, TimedAssociator)
    assert belief.associator.inner.backend == "optimal"  # type: ignore[attr-defined]
    assert belief.lrt_predictor.diffusion is world.lrt_diffusion
    assert belief.tracker_predictor.diffusion is world.tracker_diffusion
    assert belief.handover is not None
    assert LRTMissionBelief.for_mission(SCENARIO, world, np.random.default_rng(0)).handover is None


def test_bad_steps_are_refused_by_name(world: World) -> None:
    """A scan without the footprints' ζ and a prediction over another Δt are refused."""
    belief = LRTMissionBelief.for_mission(SCENARIO, world, np.random.default_rng(0))
    pos = position_measurements(UAV.xy_m, np.empty((0, 2)), SENSOR, np.random.default_rng(1))
    with pytest.raises(InvalidInputError) as info:
        belief.update(RoadScan(0.3, pos), UAV)
    assert info.value.field == "scan.lrt"
    with pytest.raises(InvalidInputError) as info:
        belief.predict(2 * SCENARIO.dt_s)
    assert info.value.field == "dt_s"


class Fixed:
    """An associator that always answers the same association."""

    backend = "fixed"

    def associate(self, bank: object, densities: object) -> Association:
        return Association(((0, 0),))


def test_timed_associator_delegates_and_laps() -> None:
    """The wrapped associator's answer is returned; a lap reports the time spent and restarts."""
    timed = TimedAssociator(Fixed())
    assert timed.associate(None, None).pairs == ((0, 0),)  # type: ignore[arg-type]
    assert timed.seconds >= 0.0
    spent = timed.lap()
    assert spent >= 0.0 and timed.seconds == 0.0 and timed.lap() == 0.0
