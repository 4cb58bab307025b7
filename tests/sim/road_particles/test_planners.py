"""The planners of closed-loop road tracking."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from searchtrack.estimate.road_rbpf import RoadRBPF
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.sim.road_particles.episode import PAPER_GRID, RoadTrackingConfig
from searchtrack.sim.road_particles.planners import PLANNERS, make_chooser


@dataclass
class _Episode:
    """The parts of an episode a chooser reads."""

    roads: DirectedRoads
    belief: RoadRBPF
    plan_rng: np.random.Generator
    targets: tuple[np.ndarray, np.ndarray]

    def truth(self) -> tuple[np.ndarray, np.ndarray]:
        return self.targets

    def uav_points(self) -> np.ndarray:
        return np.zeros((1, 2))


@pytest.fixture(scope="module")
def roads() -> DirectedRoads:
    return DirectedRoads(PAPER_GRID.build())


@pytest.mark.parametrize("planner", PLANNERS)
def test_every_planner_chooses_a_road_leaving_the_node(roads: DirectedRoads,
                                                       planner: str) -> None:
    config = RoadTrackingConfig(planner=planner, histories=2, particles=50, lookahead=2,
                                time_limit_s=2.0)
    rng = np.random.default_rng(0)
    rbpf = RoadRBPF(roads, config.filter_config(), rng)
    truth = roads.uniform(2, rng)
    choose = make_chooser(config, _Episode(roads, rbpf, rng, truth))
    for node in range(roads.network.n_nodes):
        assert choose(0, node) in set(roads.leaving(node).tolist())


def test_the_ideal_planner_heads_for_a_target(roads: DirectedRoads) -> None:
    """A target on a road leaving the UAV's node: the ideal planner takes that road."""
    config = RoadTrackingConfig(planner="ideal", histories=2, particles=50, lookahead=2)
    rng = np.random.default_rng(1)
    rbpf = RoadRBPF(roads, config.filter_config(), rng)
    road = int(roads.leaving(0)[0])
    truth = (np.array([road, road]), np.array([50.0, 60.0]))
    choose = make_chooser(config, _Episode(roads, rbpf, rng, truth))
    assert choose(0, 0) == road
