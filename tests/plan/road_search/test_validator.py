"""The independent plan check: faults are found and named, and the recomputed objective is the
scenario's (by hand on static targets, and on random plans with moving targets)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.plan.road_search import RoadPlan, RoadSearchProblem, check_plan, solve

from .helpers import edge, grid_roads, random_problem, random_roads
from .test_scenario import every_plan, static_problem


def test_objective_by_hand() -> None:
    """Path 4→3→0→1 on static targets: γ_0 + 0.8² γ_1."""
    p = static_problem()
    check = check_plan(p, RoadPlan.from_edges(p.roads, [[edge(4, 3), edge(3, 0), edge(0, 1)]]))
    assert check.feasible and not check.reasons
    assert check.objective == pytest.approx(p.gamma[0] + 0.64 * p.gamma[1], rel=1e-12)


def assert_every_plan_scores_alike(p: RoadSearchProblem) -> list[RoadPlan]:
    """Every plan of ``p`` passes the check, which scores it as the scenario does; the plans."""
    plans = every_plan(p)
    for plan in plans:
        check = check_plan(p, plan)
        assert check.feasible, check.reasons
        assert check.objective == pytest.approx(p.scenario.score(plan), rel=1e-12, abs=1e-15)
    return plans


@pytest.mark.parametrize("seed", range(4))
def test_recomputed_objective_equals_the_scenario(seed: int) -> None:
    """For every plan of a small instance with moving targets, both objectives agree."""
    roads = grid_roads() if seed % 2 else random_roads(seed)
    p = random_problem(roads, np.random.default_rng(seed), uavs=1 + seed % 2, lookahead=2,
                       per_length=seed >= 2, both_directions=seed != 1)
    assert_every_plan_scores_alike(p)


@pytest.mark.parametrize("seed", range(6))
def test_uavs_in_flight_are_scored_from_their_arrival(seed: int) -> None:
    """With UAVs still flying to their nodes, every plan's recomputed objective is the
    scenario's, and a UAV's path starts at its delay in whole ticks."""
    roads = grid_roads() if seed % 2 else random_roads(seed)
    p = random_problem(roads, np.random.default_rng(100 + seed), uavs=2, lookahead=2,
                       delayed=True)
    assert p.uav_delay_s[0] == 0.0 and p.uav_delay_s[1] > 0.0
    assert [int(lat.state_tick[0]) for lat in p.scenario.lattices] == [
        round(d / p.tick_s) for d in p.uav_delay_s]
    assert_every_plan_scores_alike(p)


@pytest.mark.parametrize("seed", range(4))
def test_time_horizon_plans_are_scored_and_their_length_checked(seed: int) -> None:
    """With a horizon: every plan's recomputed objective is the scenario's, and a path cut
    short or run on past the horizon is refused."""
    p = random_problem(random_roads(seed), np.random.default_rng(600 + seed), uavs=1,
                       lookahead=4, horizon_s=6.0)
    plans = assert_every_plan_scores_alike(p)
    short = [plan for plan in plans if len(plan.edges[0]) < p.lookahead]
    assert short, "the horizon cuts some path"
    path = list(short[0].edges[0])
    longer = [*path, int(p.roads.leaving(int(p.roads.head[path[-1]]))[0])]
    for bad in (path[:-1], longer):
        if bad:
            check = check_plan(p, RoadPlan.from_edges(p.roads, [bad]))
            assert not check.feasible and "horizon allow" in check.reasons[0]
            with pytest.raises(ValueError):
                p.scenario.score(RoadPlan.from_edges(p.roads, [bad]))


@pytest.mark.parametrize("horizon_s", [None, 5.0])
@pytest.mark.parametrize("backend", ["exhaustive", "beam", "exact", "auto", "greedy", "random"])
def test_every_backend_plan_checks(backend: str, horizon_s: float | None) -> None:
    """Each backend's plan is feasible and its objective is the recomputed one (with and
    without a time horizon, UAVs in flight)."""
    roads = grid_roads() if horizon_s is None else random_roads(2)
    p = random_problem(roads, np.random.default_rng(11), uavs=2, lookahead=3,
                       delayed=horizon_s is not None, horizon_s=horizon_s)
    res = solve(p, backend=backend, time_limit_s=10.0)
    assert res.plan is not None
    check = check_plan(p, res.plan)
    assert check.feasible and check.objective == pytest.approx(res.objective, rel=1e-12)


def test_faults_are_named() -> None:
    """Wrong start, broken path, wrong length, wrong UAV count, a missing edge, not a plan."""
    p = static_problem(lookahead=2)
    cases = {
        "starts at": RoadPlan((( 3, 0, 1),), ((edge(3, 0), edge(0, 1)),)),
        "does not go from": RoadPlan(((4, 3, 0),), ((edge(4, 3), edge(0, 1)),)),
        "look-ahead": RoadPlan.from_edges(p.roads, [[edge(4, 3)]]),
        "paths for": RoadPlan.from_edges(p.roads, [[edge(4, 3), edge(3, 0)]] * 2),
        "does not exist": RoadPlan(((4, 3, 0),), ((99, edge(3, 0)),)),
        "not a RoadPlan": "4-3-0",
    }
    for phrase, plan in cases.items():
        check = check_plan(p, plan)  # type: ignore[arg-type]
        assert not check.feasible and math.isnan(check.objective)
        assert any(phrase in r for r in check.reasons), (phrase, check.reasons)
