"""Monte Carlo campaigns: means with 95 % t-intervals, and one scenario flown over many seeds."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from searchtrack.models import SensorModel
from searchtrack.sim.campaign import Estimate, estimate, fly_seeds
from searchtrack.sim.mission import Mission, World
from searchtrack.sim.scenario import GuidanceSpec, MapSpec, Scenario

SENSOR = SensorModel(pd=0.95, pf=0.05, footprint_radius_m=150.0, position_noise_m=5.0)
TINY = Scenario("tiny", MapSpec("grid", rows=3, cols=3, block_m=100.0, spacing_m=20.0),
                uav_count=2, target_count=1, sensor=SENSOR, altitude_m=None, duration_s=1.5,
                guidance=GuidanceSpec(strategy="search"))

# Student t quantiles t_{0.975, ν} (tables): ν = 1: 12.706205, ν = 2: 4.302653.


def test_estimate_of_three_values_by_hand() -> None:
    """[1, 2, 3]: mean 2, s.d. 1, half-width t_{0.975,2}·1/√3 = 2.48414."""
    e = estimate([1.0, 2.0, 3.0])
    assert (e.n, e.mean, e.std) == (3, 2.0, 1.0)
    assert e.half_width == pytest.approx(4.302653 / math.sqrt(3), rel=1e-6)
    assert str(e) == "2 ± 2.5"


def test_estimate_drops_missing_values() -> None:
    """None, NaN and ±inf are dropped: [1, 3] gives s.d. √2 and half-width t_{0.975,1}."""
    e = estimate([1.0, None, math.nan, 3.0, math.inf, -math.inf])  # type: ignore[list-item]
    assert (e.n, e.mean) == (2, 2.0)
    assert e.std == pytest.approx(math.sqrt(2.0))
    assert e.half_width == pytest.approx(12.706205, rel=1e-6)


def test_estimate_of_no_or_one_value() -> None:
    """No value gives n = 0 and NaNs, printed "-"; one value has s.d. 0 and an infinite interval."""
    none = estimate([])
    assert none.n == 0 and math.isnan(none.mean) and str(none) == "-"
    assert estimate([None, math.nan]).n == 0  # type: ignore[list-item]
    assert estimate([5.0]) == Estimate(1, 5.0, 0.0, math.inf)


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
