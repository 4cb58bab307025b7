"""One road scenario flown over many seeds, the map and its operators built once."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence

from searchtrack.sim.roads.mission import Mission, World
from searchtrack.sim.roads.record import MissionLog
from searchtrack.sim.roads.scenario import Scenario


def fly_seeds(base: Scenario, seeds: Sequence[int], world: World | None = None,
              progress: Callable[[int], None] | None = None) -> list[MissionLog]:
    """Fly ``base`` once per seed, sharing one :class:`World` (which must match ``base``'s map,
    ``α`` and ``Δt`` when given)."""
    shared = world if world is not None else World.build(base)
    logs = []
    for i, seed in enumerate(seeds):
        logs.append(Mission(dataclasses.replace(base, seed=int(seed)), shared).run())
        if progress is not None:
            progress(i + 1)
    return logs
