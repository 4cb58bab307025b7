"""The partitioned search: the balanced partition owns every massive cell once and splits the
mass evenly, the discounted prize orders cells by arrival, the partitioned instance keeps only
the UAV's cells, and the partitioned strategies split two UAVs between two roads, are
deterministic per seed and fly a short mission."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import (
    GuidanceProblem,
    SearchCells,
    StrategyConfig,
    search_instance,
    solve,
)
from searchtrack.plan.guidance.search_partition import balanced_partition, discounted_prize
from searchtrack.plan.guidance.validate import answer_problems

from .helpers import path_road, road, view_of

CFG = StrategyConfig(sensor_range_m=30.0, speed_mps=20.0, search_horizon_s=80.0)


def test_discounted_prize_orders_by_arrival() -> None:
    """Equal mass: the nearer cell is worth more; ``τ`` halves the prize at ``t = τ``; a cell
    twice as heavy but far enough loses to a near one; bad input named."""
    p = discounted_prize([1.0, 1.0, 2.0], [0.0, 15.0, 60.0], 15.0)
    np.testing.assert_allclose(p, [1.0, 0.5, 0.4])
    assert p[0] > p[1] > p[2]
    assert np.all(np.diff(discounted_prize(np.ones(5), np.arange(5.0) * 10, 30.0)) < 0)
    with pytest.raises(InvalidInputError, match="discount_s"):
        discounted_prize([1.0], [0.0], 0.0)
    with pytest.raises(InvalidInputError, match="arrival_s"):
        discounted_prize([1.0], [-1.0], 10.0)
    with pytest.raises(InvalidInputError, match="arrival_s"):
        discounted_prize([1.0, 2.0], [1.0], 10.0)


def test_partition_owns_every_point_once_and_balances_the_mass() -> None:
    """Every point has exactly one owner among the sites; with both sites at one end of a line
    of equal masses the plain Voronoi diagram gives one site everything, the balanced one gives
    each about half, in two contiguous runs."""
    pts = np.column_stack([np.arange(40.0) * 10.0, np.zeros(40)])
    mass = np.ones(40)
    sites = np.array([[-50.0, 0.0], [-40.0, 0.0]])
    owner = balanced_partition(pts, mass, sites)
    assert owner.shape == (40,) and set(owner.tolist()) <= {0, 1}
    got = np.bincount(owner, weights=mass, minlength=2)
    assert got.sum() == pytest.approx(mass.sum())
    assert np.all(np.abs(got - 20.0) <= 2.0)
    assert np.count_nonzero(np.diff(owner)) == 1  # two runs, not interleaved
    plain = balanced_partition(pts, mass, sites, rounds=1)
    assert np.bincount(plain, minlength=2).max() <= 40
    rng = np.random.default_rng(1)
    pts3, mass3 = rng.uniform(0, 1000, (200, 2)), rng.uniform(0, 1, 200)
    sites3 = rng.uniform(0, 1000, (3, 2))
    owner3 = balanced_partition(pts3, mass3, sites3)
    shares = np.bincount(owner3, weights=mass3, minlength=3) / mass3.sum()
    assert shares.sum() == pytest.approx(1.0) and shares.min() > 0.25
    np.testing.assert_array_equal(owner3, balanced_partition(pts3, mass3, sites3))


def test_partition_edge_cases() -> None:
    """One site owns everything; no points give no owners; no mass gives the plain Voronoi
    diagram; bad input named."""
    pts = np.array([[0.0, 0.0], [100.0, 0.0]])
    np.testing.assert_array_equal(balanced_partition(pts, [1.0, 1.0], [[500.0, 0.0]]), [0, 0])
    assert balanced_partition(np.zeros((0, 2)), [], [[0.0, 0.0]]).shape == (0,)
    np.testing.assert_array_equal(
        balanced_partition(pts, [0.0, 0.0], [[0.0, 1.0], [100.0, 1.0]]), [0, 1])
    with pytest.raises(InvalidInputError, match="sites_xy"):
        balanced_partition(pts, [1.0, 1.0], np.zeros((0, 2)))
    with pytest.raises(InvalidInputError, match="mass"):
        balanced_partition(pts, [1.0, -1.0], [[0.0, 0.0]])


def test_partitioned_instance_keeps_the_uav_cells_with_discounted_scores() -> None:
    """``keep`` leaves out the other cells; ``discount_s`` scores the candidates by their
    discounted mass (nearer cells first among equal mass)."""
    net = path_road(41, 10.0)  # x = 0 .. 400
    cells = SearchCells(net, 40.0)
    mass = np.full(net.n_nodes, 1.0 / net.n_nodes)
    keep = np.zeros(cells.n_cells, dtype=bool)
    keep[cells.cell_of[net.coords[:, 0] >= 200.0]] = True
    inst, ids = search_instance(cells, mass, [0.0, 0.0], 10.0, 100.0, keep=keep,
                                discount_s=10.0)
    assert inst.n > 1 and all(net.coords[v, 0] >= 200.0 for v in ids[1:])
    scores = np.asarray(inst.profit)[1:]
    dist = net.coords[ids[1:], 0]
    assert np.all(np.diff(scores[np.argsort(dist)]) < 0)
    _, plain_ids = search_instance(cells, mass, [0.0, 0.0], 10.0, 100.0)
    assert any(net.coords[v, 0] < 200.0 for v in plain_ids[1:])
    with pytest.raises(InvalidInputError, match="keep"):
        search_instance(cells, mass, [0.0, 0.0], 10.0, 100.0, keep=np.ones(3, dtype=bool))


def _two_roads() -> RoadNetwork:
    """Two parallel 300 m roads 600 m apart (y = 0 and y = 600), nodes every 20 m."""
    xs = [20.0 * i for i in range(16)]
    coords = [(x, 0.0) for x in xs] + [(x, 600.0) for x in xs]
    edges = [(i, i + 1) for i in range(15)] + [(16 + i, 17 + i) for i in range(15)]
    return road(coords, edges)


def _problem(net: RoadNetwork, xy: list[list[float]], llr: np.ndarray,
             config: StrategyConfig = CFG) -> GuidanceProblem:
    return GuidanceProblem(view_of(net, xy, (), llr), config,
                           GraphDiffusion.on_network(net, 0.447, 0.3))


def test_two_uavs_on_one_road_split_the_two_roads() -> None:
    """Both UAVs start on the south road, both roads unexplored: the plain route strategy sends
    both to the south road they stand on, the partitioned one sends one of them north."""
    net = _two_roads()
    llr = np.zeros(net.n_nodes)
    problem = _problem(net, [[150.0, 0.0], [150.0, 60.0]], llr)
    result = solve(problem, backend="route_partition_search", time_limit_s=2.0, seed=0)
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert answer_problems(problem, result) == []
    g = result.plan
    assert g.mode == ("route", "route")
    north = [all(net.coords[v, 1] == 600.0 for v in r.nodes) for r in g.search_routes]
    south = [all(net.coords[v, 1] == 0.0 for v in r.nodes) for r in g.search_routes]
    assert sorted(north) == [False, True] and sorted(south) == [False, True]


@pytest.mark.parametrize("backend", ["route_partition_search", "route_partition_loiter"])
def test_partitioned_strategies_are_deterministic(backend: str) -> None:
    """Same problem and seeds, same answers over a chain of steps."""
    net = _two_roads()
    llr = np.random.default_rng(3).normal(size=net.n_nodes)
    runs = []
    for _ in range(2):
        problem = _problem(net, [[0.0, 0.0], [300.0, 300.0], [150.0, 600.0]], llr)
        answers = []
        for seed in (5, 6, 7):
            result = solve(problem, backend=backend, time_limit_s=2.0, seed=seed)
            assert result.plan is not None and answer_problems(problem, result) == []
            answers.append(result.plan)
            problem = problem.following(problem.view, result.plan)
        runs.append(answers)
    for a, b in zip(*runs, strict=True):
        np.testing.assert_array_equal(a.force, b.force)
        assert a.mode == b.mode and a.route == b.route and a.search_routes == b.search_routes


def test_far_part_is_reached_by_a_longer_look_ahead() -> None:
    """A look-ahead too short to reach the UAV's part of the partition is doubled until it
    does: the UAV still plans a route there (the plain strategy falls back to the gradient)."""
    net = _two_roads()
    llr = np.where(net.coords[:, 1] < 300.0, -20.0, 0.0)
    short = dataclasses.replace(CFG, search_horizon_s=20.0)  # 400 m at 20 m/s
    problem = _problem(net, [[150.0, 0.0]], llr, short)
    plain = solve(problem, backend="route_search", time_limit_s=2.0, seed=0).plan
    assert plain is not None and plain.mode == ("search",)
    part = solve(problem, backend="route_partition_search", time_limit_s=2.0, seed=0).plan
    assert part is not None and part.mode == ("route",)
    assert all(net.coords[v, 1] == 600.0 for v in part.route[0])
