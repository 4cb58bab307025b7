"""The search OPTW over the search field: the field's mass, the cells, the instance's candidates
(reachable, unclaimed, within the budget) and the route a UAV keeps flying."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.guidance import (
    SearchCells,
    SearchRoute,
    near_peaks,
    search_instance,
    search_mass,
)
from searchtrack.plan.guidance.reacquire import plan_reacquisition
from searchtrack.plan.optw.validate import validate

from .helpers import path_road


def test_search_mass_is_the_softmax_of_the_score() -> None:
    """``exp(φ)`` normalised: the LRT field's own node probability, uniform when neutral."""
    llr = np.array([0.0, -20.0, 3.0, 0.0])
    field = LikelihoodField(llr)
    np.testing.assert_allclose(search_mass(field), field.node_probability())
    np.testing.assert_allclose(search_mass(LikelihoodField(np.zeros(5))), np.full(5, 0.2))
    with pytest.raises(InvalidInputError):
        search_mass(np.zeros(3))  # type: ignore[arg-type]


def test_explained_nodes_keep_their_negative_score_only() -> None:
    """On the nodes a tracked target explains, a positive score counts as 0 and a negative one
    is kept; elsewhere the softmax is unchanged; a bad mask is refused by name."""
    field = LikelihoodField(np.array([0.0, -20.0, 3.0, 8.0, -5.0]))
    explained = np.array([False, False, False, True, True])
    expected = np.exp([0.0, -20.0, 3.0, 0.0, -5.0])
    np.testing.assert_allclose(search_mass(field, explained), expected / expected.sum())
    np.testing.assert_allclose(search_mass(field, np.zeros(5, dtype=bool)), search_mass(field))
    for bad in (np.zeros(4, dtype=bool), np.zeros(5)):
        with pytest.raises(InvalidInputError, match="explained"):
            search_mass(field, bad)


def test_near_peaks_marks_the_nodes_within_the_radius() -> None:
    """Nodes within the radius of any peak node, none without peaks; bad input named."""
    net = path_road(11)  # x = 0, 10, ..., 100
    np.testing.assert_array_equal(np.flatnonzero(near_peaks(net, [2, 9], 15.0)),
                                  [1, 2, 3, 8, 9, 10])
    assert not near_peaks(net, [], 15.0).any()
    with pytest.raises(InvalidInputError, match="peaks"):
        near_peaks(net, [11], 15.0)
    with pytest.raises(InvalidInputError, match="radius_m"):
        near_peaks(net, [2], 0.0)


def test_cells_bin_nodes_and_take_the_mass_centroid_node() -> None:
    """A 100 m path in 45 m cells: three cells; each prize is its mass, each vertex the node
    nearest the cell's mass centroid (its plain centroid when massless)."""
    net = path_road(11)  # x = 0, 10, ..., 100
    cells = SearchCells(net, 45.0)
    assert cells.n_cells == 3
    np.testing.assert_array_equal(cells.cell_of, [0] * 5 + [1] * 4 + [2] * 2)
    mass = np.zeros(11)
    mass[[0, 1]] = [0.1, 0.3]   # centroid x = 7.5 → node 1
    mass[8] = 0.6               # one node of cell 1
    total, vertex = cells.prizes(mass)
    np.testing.assert_allclose(total, [0.4, 0.6, 0.0])
    assert vertex.tolist() == [1, 8, 9]  # cell 2: centroid x = 95, tie → lower index
    with pytest.raises(InvalidInputError):
        SearchCells(net, 0.0)
    with pytest.raises(InvalidInputError):
        cells.prizes(np.full(11, -1.0))


def _route_time_s(net_xy: np.ndarray, start: np.ndarray, nodes: tuple[int, ...],
                  speed: float) -> float:
    points = np.vstack([start[None, :], net_xy[list(nodes)]])
    return float(np.hypot(*np.diff(points, axis=0).T).sum()) / speed


@pytest.mark.parametrize("seed", range(4))
def test_routes_visit_only_reachable_candidates_within_the_budget(seed: int) -> None:
    """On random fields over a grid, every route node is a candidate cell's vertex within
    reach, and the route flies within the look-ahead."""
    rng = np.random.default_rng(seed)
    net = grid_network(8, 8, 100.0, 50.0)
    cells = SearchCells(net, 70.0)
    mass = rng.random(net.n_nodes) * (rng.random(net.n_nodes) < 0.7)
    xy = rng.uniform(0.0, 700.0, 2)
    speed, horizon = 20.0, float(rng.uniform(10.0, 30.0))
    inst, ids = search_instance(cells, mass, xy, speed, horizon, max_nodes=12, serve_m=20.0)
    total, vertex = cells.prizes(mass)
    assert ids[0] == -1 and 1 <= inst.n <= 13
    reach = np.hypot(*(net.coords[ids[1:]] - xy).T)
    assert np.all(reach <= speed * horizon) and np.all(reach > 20.0)
    assert set(ids[1:].tolist()) <= set(vertex[total > 0].tolist())
    nodes, result = plan_reacquisition(inst, ids, backend="labelling", time_limit_s=5.0)
    assert result.plan is not None and validate(inst, result.plan).feasible
    assert set(nodes) <= set(ids[1:].tolist())
    assert _route_time_s(net.coords, xy, nodes, speed) <= horizon + 1e-6


def test_candidates_are_the_heaviest_unclaimed_cells() -> None:
    """``max_nodes`` keeps the heaviest cells (ties: nearer first); ``exclude`` drops the cells
    of claimed nodes; nothing within reach leaves only the start."""
    net = path_road(101)  # 0 … 1000 m
    cells = SearchCells(net, 100.0)
    mass = np.ones(101)
    mass[95:] = 5.0  # the cell 900 ≤ x < 1000 is heaviest, the others below it tie
    inst, ids = search_instance(cells, mass, np.array([0.0, 0.0]), 10.0, 200.0, max_nodes=2)
    kept = cells.cell_of[ids[1:]].tolist()
    assert kept == [cells.cell_of[95], cells.cell_of[0]]  # the heaviest, then the nearest
    inst, ids = search_instance(cells, mass, np.array([0.0, 0.0]), 10.0, 200.0, max_nodes=2,
                                exclude=[97])
    assert cells.cell_of[ids[1:]].tolist() == [cells.cell_of[0], cells.cell_of[10]]
    inst, ids = search_instance(cells, mass, np.array([0.0, 5000.0]), 10.0, 200.0)
    assert inst.n == 1 and ids.tolist() == [-1]
    with pytest.raises(InvalidInputError):
        search_instance(cells, mass, np.array([0.0, 0.0]), 10.0, -1.0)
    with pytest.raises(InvalidInputError):
        search_instance(cells, mass, np.array([0.0, 0.0]), 10.0, 10.0, exclude=[500])


def test_search_route_is_due_when_reached_or_old() -> None:
    """A route is planned again once its first node is within ``serve_m`` or it has aged."""
    net = path_road(20)
    route = SearchRoute(0, (10, 15), 5.0)
    far, near = np.array([[0.0, 0.0]]), np.array([[95.0, 0.0]])
    assert not route.due(net, far, 6.0, 10.0, 10.0)
    assert route.due(net, near, 6.0, 10.0, 10.0)
    assert route.due(net, far, 15.0, 10.0, 10.0)
    for bad in ({"nodes": ()}, {"nodes": (-1,)}, {"planned_s": math.nan}, {"uav": -1}):
        args = {"uav": 0, "nodes": (1,), "planned_s": 0.0} | bad
        with pytest.raises(InvalidInputError):
            SearchRoute(**args)  # type: ignore[arg-type]
