"""The planners of closed-loop road tracking."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from searchtrack.core.result import Result
from searchtrack.estimate.road_rbpf import RoadRBPF
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.plan.road_search import RoadPlan, RoadSearchProblem, solve
from searchtrack.sim.road_particles import planners
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

    arriving: tuple[np.ndarray, np.ndarray] = (np.zeros(1, dtype=np.int64), np.zeros(1))

    def uav_points(self) -> np.ndarray:
        return np.zeros((self.arriving[0].size, 2))

    def uav_arrivals(self) -> tuple[np.ndarray, np.ndarray]:
        return self.arriving


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


@pytest.mark.parametrize("coordination", ["joint", "alone"])
def test_joint_decisions_plan_every_uav(roads: DirectedRoads, coordination: str,
                                        monkeypatch: pytest.MonkeyPatch) -> None:
    """Joint: UAV 1 deciding at node 0 plans with UAV 0 (flying to node 8, 1.5 s away) and UAV
    2 (at node 4 now), and flies the first edge of its own path; alone: it plans by itself."""
    config = RoadTrackingConfig(uavs=3, coordination=coordination,  # type: ignore[arg-type]
                                histories=2, particles=50, lookahead=2)
    rng = np.random.default_rng(2)
    rbpf = RoadRBPF(roads, config.filter_config(), rng)
    seen: list[RoadSearchProblem] = []

    def spy(problem: RoadSearchProblem, **kwargs: object) -> Result[RoadPlan]:
        seen.append(problem)
        return planners.BACKENDS.solve("exhaustive", problem, time_limit_s=5.0, seed=0)

    monkeypatch.setattr(planners, "solve", spy)
    arriving = (np.array([8, 3, 4]), np.array([1.5, 0.7, 0.0]))
    choose = make_chooser(config, _Episode(roads, rbpf, rng, roads.uniform(2, rng), arriving))
    edge = choose(1, 0)
    (problem,) = seen
    if coordination == "joint":
        assert problem.uav_nodes == (8, 0, 4) and problem.uav_delay_s == (1.5, 0.0, 0.0)
        plan = solve(problem, backend="exhaustive", time_limit_s=5.0).plan
        assert plan is not None and edge == plan.first_edges[1]
    else:
        assert problem.uav_nodes == (0,) and problem.uav_delay_s == (0.0,)
    assert edge in set(roads.leaving(0).tolist())
