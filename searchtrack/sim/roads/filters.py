"""The filters a thesis 001 road mission can fly, by the name a scenario gives as
``filter.belief``.

Each registration names the filter, how to build it for a scenario on a world, and what its
updates read from the sensors; the mission steps whatever it builds through the
:class:`~searchtrack.estimate.stepping.RoadFilter` protocol. A new filter is its own module (a
class with the protocol's verbs and views, and a builder) plus one ``FILTERS.register`` line
below.

- ``"lrt"``: the thesis's likelihood-ratio field and node trackers
  (:mod:`searchtrack.sim.roads.lrt_belief`); reads the footprints' ``ζ`` and the position fixes.
- ``"rbpf"``: paper 000's Rao-Blackwellized particle filter
  (:mod:`searchtrack.sim.roads.rbpf_belief`); reads the position fixes only.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from searchtrack.core.registry import NameTable
from searchtrack.estimate.stepping import RoadFilter
from searchtrack.sim.roads.lrt_belief import LRTMissionBelief
from searchtrack.sim.roads.rbpf_belief import RBPFMissionBelief, searches_on_lrt
from searchtrack.sim.roads.scenario import Scenario
from searchtrack.sim.roads.world import World

#: First word of a mission filter's random stream ``(FILTER_STREAM, seed)``: apart from the
#: stream of the mission's world (the targets, the sensors, the guidance seeds).
FILTER_STREAM = 1


@dataclass(frozen=True)
class MissionFilter:
    """One filter a road mission can fly.

    Parameters
    ----------
    name
        The ``filter.belief`` of the scenarios that fly it.
    build
        ``build(scenario, world, rng)``: a fresh filter for one mission, owning ``rng``.
    reads_lrt
        Whether its updates read the per-node ``ζ`` of the footprints (:class:`~searchtrack.
        models.measurements.LrtScan`) besides the position fixes, always or per scenario;
        when not, the sensors do not draw them.
    description
        One line for listings.
    """

    name: str
    build: Callable[[Scenario, World, np.random.Generator], RoadFilter]
    reads_lrt: bool | Callable[[Scenario], bool]
    description: str

    def reads_lrt_of(self, scenario: Scenario) -> bool:
        """Whether the filter of ``scenario`` reads the footprints' ``ζ``."""
        return self.reads_lrt if isinstance(self.reads_lrt, bool) else self.reads_lrt(scenario)

    def filter_for(self, scenario: Scenario, world: World) -> RoadFilter:
        """A fresh filter for a mission of ``scenario``, drawing from the stream
        ``(FILTER_STREAM, scenario.seed)``."""
        return self.build(scenario, world, np.random.default_rng([FILTER_STREAM, scenario.seed]))


FILTERS: NameTable[MissionFilter] = NameTable("road mission filter", "filter.belief")
"""The filters of road missions."""

FILTERS.register(MissionFilter("lrt", LRTMissionBelief.for_mission, reads_lrt=True,
                               description="thesis 001: LRT field and node trackers"))
FILTERS.register(MissionFilter("rbpf", RBPFMissionBelief.for_mission,
                               reads_lrt=searches_on_lrt,
                               description="paper 000: Rao-Blackwellized particle filter"))
