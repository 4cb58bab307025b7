"""How recently the fleet covered each road node: the state behind the coverage force of the
search guidance (a rule of this library; thesis 001's search climbs the LRT alone).

Each step every road node within the sensor footprint radius ``ρ`` of a UAV is stamped with the
time; a node's coverage ``c(v) = exp(−(t − t_v)/τ)`` is 1 just after it was covered and fades
to 0 (0 for a node never covered). The default memory ``τ`` is the LRT's own: (3.6) relaxes
``φ`` toward neutral at the rate ``α/C``, so negative evidence of a look fades over ``C/α``
(≈ 112 s with Table 6.4's ``C`` = 50, ``α`` = 0.447). The mission keeps one when its guidance
has a positive ``coverage_weight`` and hands :meth:`CoverageMemory.level` to the guidance view.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.checks import positive, real
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models import RoadNetwork


@dataclass(eq=False)
class CoverageMemory:
    """Per road node, the last time a UAV footprint covered it (``-inf``: never).

    Parameters
    ----------
    network
        The road network.
    radius_m
        The footprint radius ``ρ`` (m), > 0.
    memory_s
        The fading time ``τ`` (s) of :meth:`level`, > 0.
    """

    network: RoadNetwork
    radius_m: float
    memory_s: float
    last_s: FloatArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        self.radius_m = positive("radius_m", self.radius_m)
        self.memory_s = positive("memory_s", self.memory_s)
        self.last_s = np.full(self.network.n_nodes, -np.inf)

    def see(self, uav_xy_m: ArrayLike, time_s: float) -> None:
        """Stamp the nodes within ``radius_m`` of any UAV at ``uav_xy_m`` with ``time_s``."""
        t = real("time_s", time_s)
        _, nodes = self.network.nodes_within(uav_xy_m, self.radius_m)
        self.last_s[nodes] = t

    def level(self, time_s: float) -> FloatArray:
        """``(n,)`` coverage ``exp(−(time_s − t_v)/τ)`` in ``[0, 1]`` (0 where never covered)."""
        t = real("time_s", time_s)
        age = np.maximum(t - self.last_s, 0.0)
        return np.asarray(np.exp(-age / self.memory_s), dtype=np.float64)
