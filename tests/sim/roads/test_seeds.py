"""One road scenario flown over many seeds on one world."""

from __future__ import annotations

import dataclasses

import numpy as np

from searchtrack.models import SensorModel
from searchtrack.sim.roads.mission import Mission, World
from searchtrack.sim.roads.scenario import GuidanceSpec, MapSpec, Scenario
from searchtrack.sim.roads.seeds import fly_seeds

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)
TINY = Scenario("tiny", MapSpec("grid", rows=3, cols=3, block_m=100.0, spacing_m=20.0),
                uav_count=2, target_count=1, sensor=SENSOR, altitude_m=None, duration_s=1.5,
                guidance=GuidanceSpec(strategy="search"))


def test_fly_seeds_flies_each_seed_on_one_world() -> None:
    """One log per seed, in order, equal to a mission flown alone with that seed; progress
    counts the missions flown."""
    world = World.build(TINY)
    done: list[int] = []
    logs = fly_seeds(TINY, [4, 9], world, progress=done.append)
    assert [log.scenario.seed for log in logs] == [4, 9] and done == [1, 2]
    alone = Mission(dataclasses.replace(TINY, seed=9), world).run()
    np.testing.assert_array_equal(logs[1].uav_xy_m, alone.uav_xy_m)
    np.testing.assert_array_equal(logs[1].final_llr, alone.final_llr)
    assert not np.array_equal(logs[0].uav_xy_m, logs[1].uav_xy_m)
    built = fly_seeds(TINY, [4])  # the world built from the scenario
    np.testing.assert_array_equal(built[0].uav_xy_m, logs[0].uav_xy_m)
