"""The one-step planner (Eq. 21): the paper's Fig. 2 failure of the naive value and its fix by
entropy weights, optimality for one edge and one UAV, sharing what earlier UAVs see."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.road_search import RoadSearchProblem, RoadSearchSettings, solve
from searchtrack.plan.road_search.exhaustive import solve_exhaustive
from searchtrack.plan.road_search.greedy import greedy_paths, solve_greedy

from .helpers import STATIC, edge, grid_roads, random_problem


def fig2_problem(weighting: str, backend_lookahead: int = 1) -> RoadSearchProblem:
    """The UAV at the centre; the tight target (entropy 0.5) sits on road 4–3, the spread one
    (entropy 3) is smeared over roads 4–5, 5–2 and 5–8."""
    n = 300
    tight_e = np.full(n, edge(4, 3))
    tight_s = np.linspace(40.0, 60.0, n)
    spread_e = np.repeat([edge(4, 5), edge(5, 2), edge(5, 8)], n // 3)
    spread_s = np.tile(np.linspace(0.0, 100.0, n // 3), 3)
    settings = RoadSearchSettings(lookahead=backend_lookahead, motion=STATIC,
                                  weighting=weighting)  # type: ignore[arg-type]
    return RoadSearchProblem(grid_roads(), (4,), np.stack([tight_e, spread_e]),
                             np.stack([tight_s, spread_s]), np.ones((2, n)),
                             np.array([0.5, 3.0]), settings)


def test_naive_weights_chase_the_tight_target() -> None:
    """Eq. 17 (γ = 1): the whole tight cloud on road 4–3 outweighs a third of the spread one."""
    res = solve_greedy(fig2_problem("uniform"))
    assert res.plan is not None and res.plan.next_nodes == (3,)


def test_entropy_weights_go_to_the_spread_target() -> None:
    """Eq. 20–21: the tight target's weight is small, so the UAV heads for the spread one,
    with any backend and a longer look-ahead too."""
    res = solve_greedy(fig2_problem("entropy"))
    assert res.plan is not None and res.plan.next_nodes == (5,)
    for backend in ("exhaustive", "beam", "exact", "auto"):
        longer = solve(fig2_problem("entropy", 3), backend=backend, time_limit_s=10.0)
        assert longer.plan is not None and longer.plan.next_nodes == (5,), backend


@pytest.mark.parametrize("seed", range(5))
def test_one_edge_one_uav_is_optimal(seed: int) -> None:
    """With L = 1 and one UAV the greedy edge is the best plan."""
    p = random_problem(grid_roads(), np.random.default_rng(seed), lookahead=1,
                       per_length=bool(seed % 2))
    res = solve_greedy(p)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(solve_exhaustive(p).objective, rel=1e-12)


def test_later_uavs_do_not_count_what_earlier_ones_see() -> None:
    """Two UAVs at the centre over one tight cloud: the second takes another road."""
    p = fig2_problem("uniform")
    two = RoadSearchProblem(p.roads, (4, 4), p.particle_edge, p.particle_s, p.particle_weight,
                            p.entropy, p.settings)
    paths = greedy_paths(two)
    assert paths[0] == [edge(4, 3)] and paths[1] == [edge(4, 5)]
    res = solve_greedy(two)  # all of the tight cloud and a third of the spread one: the bound
    assert res.status is Status.OPTIMAL and res.objective == pytest.approx(4.0 / 3.0)
