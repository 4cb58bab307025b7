"""The exhaustive RHC: optimal against brute force for one and two UAVs, the sequential
fallback, the size check and the time limit."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.road_search import RoadSearchProblem, check_plan, exhaustive
from searchtrack.plan.road_search.exhaustive import solve_exhaustive, supports_exhaustive

from .helpers import grid_roads, random_problem, random_roads
from .test_scenario import every_plan


@pytest.mark.parametrize(("seed", "uavs", "lookahead"),
                         [(0, 1, 1), (1, 1, 3), (2, 2, 1), (3, 2, 2), (4, 2, 3), (5, 1, 4)])
def test_optimal_against_brute_force(seed: int, uavs: int, lookahead: int) -> None:
    """OPTIMAL, and the best score over every joint plan."""
    roads = grid_roads() if seed % 2 else random_roads(seed)
    p = random_problem(roads, np.random.default_rng(seed), uavs=uavs, lookahead=lookahead)
    res = solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and res.plan is not None
    best = max(p.scenario.score(plan) for plan in every_plan(p))
    assert res.objective == pytest.approx(best, rel=1e-12)
    assert res.bound == res.objective and res.gap == 0.0


@pytest.mark.parametrize("seed", range(8))
def test_joint_plan_with_uavs_in_flight_against_brute_force(seed: int) -> None:
    """Two UAVs, the second still flying to its node: OPTIMAL, and the best of every joint
    plan as the independent check scores them."""
    roads = grid_roads() if seed % 2 else random_roads(seed)
    p = random_problem(roads, np.random.default_rng(200 + seed), uavs=2,
                       lookahead=1 + seed % 3, delayed=True)
    res = solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and res.objective is not None
    best = max(check_plan(p, plan).objective for plan in every_plan(p))
    assert res.objective == pytest.approx(best, rel=1e-12, abs=1e-15)


@pytest.mark.parametrize("seed", range(10))
def test_time_horizon_against_brute_force(seed: int) -> None:
    """Paths up to a time horizon on maps of unequal roads (one or two UAVs, some in flight):
    OPTIMAL, the best of every joint plan as the independent check scores them, and every
    path ends at the first node at or past the horizon."""
    roads = random_roads(seed) if seed % 3 else grid_roads()
    p = random_problem(roads, np.random.default_rng(400 + seed), uavs=1 + seed % 2,
                       lookahead=4, delayed=seed % 4 == 1)


    def at(ticks: int) -> RoadSearchProblem:
        settings = dataclasses.replace(p.settings, horizon_s=ticks * p.tick_s)
        return dataclasses.replace(p, settings=settings)

    def lengths(q: RoadSearchProblem) -> set[int]:
        return {len(e) for plan in every_plan(q) for e in plan.edges}

    # the shortest horizon (in whole ticks) past a few edges' time at which paths end after
    # different numbers of edges (the grid's equal roads never do)
    tries = range(2 + seed, 4 * int(p.edge_ticks.max()) + 3 + seed)
    p = next((at(k) for k in tries if len(lengths(at(k))) > 1), at(3))
    assert len(lengths(p)) > 1 or seed % 3 == 0
    plans = every_plan(p)
    res = solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and res.plan is not None
    check = check_plan(p, res.plan)
    assert check.feasible
    best = max(check_plan(p, plan).objective for plan in plans)
    assert res.objective == pytest.approx(best, rel=1e-12, abs=1e-15)
    assert check.objective == pytest.approx(res.objective, rel=1e-12, abs=1e-15)


def test_sequential_fallback_is_feasible(monkeypatch: pytest.MonkeyPatch) -> None:
    """Above the joint work limit the UAVs plan in turn: FEASIBLE, a valid bound, and no
    better than the joint optimum."""
    p = random_problem(grid_roads(), np.random.default_rng(8), uavs=2, lookahead=3)
    joint = solve_exhaustive(p)
    monkeypatch.setattr(exhaustive, "MAX_JOINT_WORK", 0)
    seq = solve_exhaustive(p)
    assert seq.status in (Status.FEASIBLE, Status.OPTIMAL) and seq.objective is not None
    assert joint.objective is not None and seq.objective <= joint.objective + 1e-12
    assert seq.bound is not None and seq.bound >= joint.objective - 1e-12
    assert "sequential" in seq.message


def test_supports_refuses_huge_trees(monkeypatch: pytest.MonkeyPatch) -> None:
    """More paths than MAX_PATHS: the backend declines with the count."""
    p = random_problem(grid_roads(), np.random.default_rng(0), lookahead=3)
    assert supports_exhaustive(p) is None
    monkeypatch.setattr(exhaustive, "MAX_PATHS", 5)
    reason = supports_exhaustive(p)
    assert reason is not None and "exceed 5" in reason


@pytest.mark.parametrize("uavs", [1, 2])
def test_time_limit_gives_no_plan_but_a_valid_bound(uavs: int) -> None:
    """A limit that expires at once: NO_SOLUTION, no plan, a bound above the optimum."""
    p = random_problem(grid_roads(), np.random.default_rng(9), uavs=uavs, lookahead=3)
    best = solve_exhaustive(p).objective
    res = solve_exhaustive(p, time_limit_s=1e-9)
    assert res.status is Status.NO_SOLUTION and res.plan is None
    assert best is not None and res.bound is not None and res.bound >= best
