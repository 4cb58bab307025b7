"""The CP-SAT maximum coverage program: agreement with the exhaustive RHC, the nested cover
coefficients, warm starts, and the time-limit and stop-request semantics (status and bound)."""

from __future__ import annotations

import threading

import numpy as np
import pytest

from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.core.result import Status
from searchtrack.plan.road_search import RoadSearchProblem, RoadSearchSettings, check_plan, solve
from searchtrack.plan.road_search.beam import solve_beam
from searchtrack.plan.road_search.exact import build_model, nested_covers, solve_exact
from searchtrack.plan.road_search.exhaustive import solve_exhaustive
from searchtrack.plan.road_search.greedy import solve_greedy

from .helpers import grid_roads, random_problem, random_roads, uniform_belief


def hard_problem() -> RoadSearchProblem:
    """Four UAVs, five edges each, on the grid: CP-SAT needs seconds to prove it."""
    belief = uniform_belief(grid_roads(), 3, 300, np.random.default_rng(0))
    return RoadSearchProblem.from_belief(belief, [4, 0, 8, 2],
                                         settings=RoadSearchSettings(lookahead=5))


@pytest.fixture(autouse=True)
def _no_stop_left() -> object:
    clear_stop()
    yield
    clear_stop()


@pytest.mark.parametrize(("seed", "uavs", "lookahead", "per_length"),
                         [(0, 1, 3, False), (1, 2, 2, True), (2, 2, 3, False),
                          (3, 1, 4, True), (4, 2, 1, False)])
def test_exact_matches_exhaustive(seed: int, uavs: int, lookahead: int,
                                  per_length: bool) -> None:
    """OPTIMAL with the exhaustive objective, on the grid and on a random map."""
    roads = grid_roads() if seed % 2 else random_roads(seed)
    p = random_problem(roads, np.random.default_rng(seed), uavs=uavs, lookahead=lookahead,
                       per_length=per_length)
    res, ref = solve_exact(p, time_limit_s=30.0), solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and ref.objective is not None
    assert res.objective == pytest.approx(ref.objective, rel=1e-7)
    assert res.bound is not None and res.bound >= ref.objective * (1 - 1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_exact_matches_exhaustive_with_uavs_in_flight(seed: int) -> None:
    """A UAV still flying to its node: the same optimum as the joint enumeration."""
    p = random_problem(grid_roads() if seed % 2 else random_roads(seed),
                       np.random.default_rng(300 + seed), uavs=2, lookahead=2, delayed=True)
    res, ref = solve_exact(p, time_limit_s=30.0), solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and ref.objective is not None
    assert res.objective == pytest.approx(ref.objective, rel=1e-7)


@pytest.mark.parametrize("seed", range(3))
def test_exact_matches_exhaustive_with_a_time_horizon(seed: int) -> None:
    """Paths up to a time horizon (hold arcs after it): the same optimum as the enumeration."""
    p = random_problem(random_roads(seed), np.random.default_rng(500 + seed), uavs=2,
                       lookahead=4, delayed=True, horizon_s=8.0)
    res, ref = solve_exact(p, time_limit_s=30.0), solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and ref.objective is not None and res.plan is not None
    assert res.objective == pytest.approx(ref.objective, rel=1e-7)
    assert check_plan(p, res.plan).feasible


def test_nested_coefficients_add_up_to_the_best_sighting() -> None:
    """Summed over a group's nested sets the coefficients give V_g times its best β."""
    p = random_problem(grid_roads(), np.random.default_rng(5), uavs=2, lookahead=3,
                       per_length=True)
    sc = p.scenario
    total = sum(nested_covers(sc).values())
    assert total == pytest.approx(float(sc.group_value @ sc.cover.max(axis=0)), rel=1e-12)
    mdl = build_model(sc)
    assert [len(x) for x in mdl.x] == [lat.n_arcs for lat in sc.lattices]


def test_warm_start_is_never_lost() -> None:
    """Given the greedy plan and almost no time, the answer is at least as good."""
    p = hard_problem()
    start = solve_greedy(p)
    assert start.plan is not None and start.objective is not None
    res = solve_exact(p, time_limit_s=0.05, initial=start.plan)
    assert res.status in (Status.FEASIBLE, Status.OPTIMAL) and res.objective is not None
    assert res.objective >= start.objective - 1e-12


def test_time_limit_keeps_a_valid_bound() -> None:
    """Cut short, CP-SAT answers FEASIBLE (or NO_SOLUTION) with a bound above the beam's and
    above its own objective; the gap says how far it is from proven."""
    p = hard_problem()
    res = solve_exact(p, time_limit_s=0.3)
    beam = solve_beam(p)
    assert res.status in (Status.FEASIBLE, Status.NO_SOLUTION)
    assert res.bound is not None and beam.objective is not None
    assert res.bound >= beam.objective
    if res.status is Status.FEASIBLE:
        assert res.objective is not None and res.bound >= res.objective
        assert res.gap is not None and res.gap > 0.0


def test_stop_request_interrupts_the_search() -> None:
    """A stop request during the solve ends CP-SAT: INTERRUPTED with the best plan and a
    valid bound, long before the time limit."""
    p = hard_problem()
    p.scenario  # noqa: B018  (build the scenario before the clock starts)
    timer = threading.Timer(0.3, request_stop)
    timer.start()
    try:
        res = solve(p, backend="exact", time_limit_s=300.0)
    finally:
        timer.cancel()
    assert res.status is Status.INTERRUPTED
    assert res.runtime_s < 100.0
    assert res.bound is not None
    if res.plan is not None:
        assert res.objective is not None and res.objective <= res.bound


def test_stop_requested_before_the_solve() -> None:
    """With a stop already requested no search runs: INTERRUPTED, no plan."""
    p = random_problem(grid_roads(), np.random.default_rng(1), lookahead=2)
    request_stop()
    res = solve(p, backend="exact", time_limit_s=10.0)
    assert res.status is Status.INTERRUPTED and res.plan is None
