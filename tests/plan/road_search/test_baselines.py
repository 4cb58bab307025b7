"""The random and ideal baselines: valid paths, determinism for a seed, U-turns allowed for
random, and the ideal planner heading for the most uncertain true target."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.road_search import RoadSearchProblem, check_plan, solve
from searchtrack.plan.road_search.baselines import ideal_path, solve_ideal, solve_random

from .helpers import edge, grid_roads, random_problem, random_roads


def with_truth(p: RoadSearchProblem, truth_edge: list[int], truth_s: list[float],
               entropy: list[float], nodes: tuple[int, ...] = (0,)) -> RoadSearchProblem:
    return RoadSearchProblem(p.roads, nodes, p.particle_edge, p.particle_s, p.particle_weight,
                             np.array(entropy), p.settings, np.array(truth_edge),
                             np.array(truth_s))


def test_random_paths_are_valid_and_seeded() -> None:
    """Random plans follow the roads, repeat for a seed and differ across seeds."""
    p = random_problem(grid_roads(), np.random.default_rng(0), uavs=2, lookahead=4)
    plans = [solve_random(p, seed=s).plan for s in range(12)]
    assert all(plan is not None and check_plan(p, plan).feasible for plan in plans)
    assert solve_random(p, seed=3).plan == plans[3]
    assert len({plan for plan in plans}) > 1


def test_random_planner_may_turn_back() -> None:
    """U-turns are allowed (all neighbours are candidates, as in the authors' code)."""
    p = random_problem(grid_roads(), np.random.default_rng(1), lookahead=4)
    turned = False
    for seed in range(40):
        plan = solve_random(p, seed=seed).plan
        assert plan is not None
        edges = plan.edges[0]
        turned |= any(b == a ^ 1 for a, b in itertools.pairwise(edges))
    assert turned


def test_ideal_heads_for_the_most_uncertain_true_target() -> None:
    """From corner 0, target 1 (entropy 4) on road 5–8 is the goal: 0→1→2→5 or 0→3→4→5 (both
    200 m), then along road 5–8 towards it."""
    p = random_problem(grid_roads(), np.random.default_rng(2), lookahead=4)
    q = with_truth(p, [edge(3, 6), edge(5, 8)], [50.0, 30.0], [1.0, 4.0])
    res = solve_ideal(q)
    assert res.status in (Status.FEASIBLE, Status.OPTIMAL) and res.plan is not None
    nodes = res.plan.nodes[0]
    assert nodes[3] == 5 and nodes[4] == 8
    assert check_plan(q, res.plan).feasible


def test_ideal_approaches_from_the_nearer_end() -> None:
    """A target 90 m along road 3→4 is reached from node 4's side: from node 5, fly 5→4 and
    then along the road 4→3 towards it; short paths continue straight on."""
    p = random_problem(grid_roads(), np.random.default_rng(3), lookahead=3)
    q = with_truth(p, [edge(3, 4), edge(3, 4)], [90.0, 90.0], [1.0, 1.0], nodes=(5,))
    path = ideal_path(q, 5, 0)
    assert path[:2] == [edge(5, 4), edge(4, 3)] and len(path) == 3
    assert q.roads.tail[path[2]] == 3 and path[2] != edge(3, 4)


def test_ideal_assigns_targets_to_uavs() -> None:
    """UAV q goes for the q-th most uncertain target."""
    p = random_problem(grid_roads(), np.random.default_rng(4), lookahead=2)
    q = with_truth(p, [edge(0, 1), edge(7, 8)], [50.0, 50.0], [3.0, 1.0], nodes=(4, 4))
    res = solve_ideal(q)
    assert res.plan is not None
    assert res.plan.edges[0][1] in (edge(1, 0), edge(0, 1), edge(3, 0), edge(1, 2))
    assert res.plan.nodes[0][1] in (1, 3) and res.plan.nodes[1][1] in (5, 7)


def test_ideal_needs_the_truth() -> None:
    """Without true positions the registry refuses the ideal backend; called directly it
    answers ERROR."""
    p = random_problem(random_roads(1), np.random.default_rng(5), lookahead=2)
    with pytest.raises(InvalidInputError, match="truth"):
        solve(p, backend="ideal")
    assert solve_ideal(p).status is Status.ERROR
