"""Small maps, a fake particle belief and random instances shared by the road-search tests."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from searchtrack.models.road_particles import DirectedRoads, RoadMotion
from searchtrack.models.road_synthetic import grid_network, random_network
from searchtrack.plan.road_search import RoadSearchProblem, RoadSearchSettings

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: Directed edges of the paper's 3×3 grid (100 m roads, node ``3r + c`` at ``(100r, 100c)``):
#: road ``k`` joins ``GRID_ROADS[k]``, edge ``2k`` runs from the lower node to the higher.
GRID_ROADS = [(0, 1), (0, 3), (1, 2), (1, 4), (2, 5), (3, 4), (3, 6), (4, 5), (4, 7), (5, 8),
              (6, 7), (7, 8)]


def edge(a: int, b: int) -> int:
    """The directed grid edge from node ``a`` to node ``b``."""
    k = GRID_ROADS.index((min(a, b), max(a, b)))
    return 2 * k if a < b else 2 * k + 1


def grid_roads() -> DirectedRoads:
    """The paper's map: 3×3 intersections, 100 m apart, 24 directed edges."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def random_roads(seed: int = 3) -> DirectedRoads:
    """A small random planar map of unequal roads (one edge per road)."""
    return DirectedRoads(random_network(7, 300.0, spacing_m=1000.0, seed=seed))


STATIC = RoadMotion(speed_mps=0.0, sigma_mps=0.0)
"""Targets that never move (hand-computed objectives)."""


@dataclass
class FakeBelief:
    """A :class:`~searchtrack.estimate.belief.RoadParticleBelief` holding fixed clouds."""

    roads: DirectedRoads
    edge: IntArray
    s: FloatArray
    w: FloatArray
    entropy: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def n_targets(self) -> int:
        return int(self.edge.shape[0])

    def target_particles(self) -> tuple[IntArray, FloatArray, FloatArray]:
        return self.edge.copy(), self.s.copy(), self.w.copy()

    def target_entropy(self) -> FloatArray:
        return self.entropy.copy()


def uniform_belief(roads: DirectedRoads, targets: int, particles: int,
                   rng: np.random.Generator) -> FakeBelief:
    """Particles spread uniformly over the roads, random entropies."""
    e, s = roads.uniform((targets, particles), rng)
    return FakeBelief(roads, e, s, np.full((targets, particles), 1.0 / particles),
                      rng.uniform(0.5, 5.0, targets))


def clustered_belief(roads: DirectedRoads, targets: int, particles: int,
                     rng: np.random.Generator, spread_m: float = 150.0) -> FakeBelief:
    """Each target's particles spread up to ``spread_m`` ahead of a random point."""
    e0, s0 = roads.uniform((targets,), rng)
    e = np.repeat(e0[:, None], particles, axis=1)
    s = np.repeat(s0[:, None], particles, axis=1)
    e, s = roads.advance(e, s, rng.uniform(0.0, spread_m, (targets, particles)), rng)
    return FakeBelief(roads, e, s, np.full((targets, particles), 1.0 / particles),
                      rng.uniform(0.5, 5.0, targets))


def random_problem(roads: DirectedRoads, rng: np.random.Generator, *, uavs: int = 1,
                   lookahead: int = 3, targets: int = 2, particles: int = 100,
                   per_length: bool = False, both_directions: bool = True,
                   draw_seed: int = 0, delayed: bool = False,
                   horizon_s: float | None = None) -> RoadSearchProblem:
    """Random UAV nodes and a random (uniform or clustered) belief on ``roads``; ``delayed``:
    every UAV but the first still in flight to its node (0–15 s away); ``horizon_s``: paths
    up to that time (``lookahead`` edges at most)."""
    make = uniform_belief if rng.random() < 0.5 else clustered_belief
    belief = make(roads, targets, particles, rng)
    nodes = rng.integers(roads.network.n_nodes, size=uavs)
    delay = rng.uniform(0.0, 15.0, uavs) * (np.arange(uavs) > 0) if delayed else np.zeros(0)
    settings = RoadSearchSettings(lookahead=lookahead, per_length=per_length,
                                  both_directions=both_directions, draw_seed=draw_seed,
                                  horizon_s=horizon_s)
    return RoadSearchProblem.from_belief(belief, [int(v) for v in nodes], settings=settings,
                                         uav_delay_s=[float(d) for d in delay])
