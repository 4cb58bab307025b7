"""The world a road scenario builds once: its network and diffusions, and the check that a
world fits a scenario."""

from __future__ import annotations

import dataclasses
import math

from searchtrack.sim.roads.scenario import FilterSpec, MapSpec, Scenario
from searchtrack.sim.roads.world import World

SCENARIO = Scenario("w", MapSpec("grid", rows=3, cols=3, block_m=100.0), uav_count=1,
                    target_count=1, altitude_m=None, seed=1)


def test_build_prepares_the_scenarios_diffusions() -> None:
    """The LRT diffuses at α with decay C, the trackers at α without decay, both over Δt, with
    their operators built; a given network is reused."""
    world = World.build(SCENARIO)
    f = SCENARIO.filter
    lrt, trk = world.lrt_diffusion, world.tracker_diffusion
    assert (lrt.alpha, lrt.decay_c, lrt.dt_s) == (f.alpha, f.decay_c, SCENARIO.dt_s)
    assert trk.alpha == f.alpha and math.isinf(trk.decay_c) and trk.dt_s == SCENARIO.dt_s
    assert lrt.operator is not None and trk.operator is not None
    again = World.build(SCENARIO, world.network)
    assert again.network is world.network
    assert world.mismatch(SCENARIO) is None


def test_mismatch_names_what_differs() -> None:
    """A scenario of another tracker diffusivity or time step is told apart, by field."""
    world = World.build(SCENARIO)
    other = dataclasses.replace(SCENARIO, filter=FilterSpec(tracker_alpha=0.9), dt_s=0.5)
    why = world.mismatch(other)
    assert why is not None
    assert "filter.tracker_alpha" in why and "dt_s" in why and "filter.decay_c" not in why
