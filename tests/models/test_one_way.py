"""One-way streets: streets are whole blocks, one-way blocks are oriented, routes obey arcs."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import csgraph

from searchtrack.models import RoadNetwork, grid_network
from searchtrack.models.one_way import one_way_roads, street_labels
from searchtrack.models.road_traces import TaxiModel, taxi_traces


@pytest.fixture(scope="module")
def grid() -> RoadNetwork:
    """A 4 × 4 grid of 100 m blocks, nodes every 10 m."""
    return grid_network(4, 4, 100.0, 10.0)


def test_streets_are_blocks(grid: RoadNetwork) -> None:
    """Blocks between intersections are streets of 10 edges; the 4 corners join 2 blocks."""
    labels = street_labels(grid)
    assert labels.max() + 1 == 4 * 3 + 4 * 3 - 4
    assert sorted(np.bincount(labels).tolist()) == [10] * 16 + [20] * 4


def test_no_one_way_streets_gives_a_symmetric_graph(grid: RoadNetwork) -> None:
    """With fraction 0 every edge is an arc both ways and every node is reachable."""
    roads = one_way_roads(grid, 0.0, np.random.default_rng(0))
    adj = roads.adjacency
    assert adj.nnz == 2 * grid.n_edges
    assert abs(adj - adj.T).max() == 0.0
    assert roads.reachable.size == grid.n_nodes and not roads.one_way.any()


def test_all_one_way_streets_are_consistently_oriented(grid: RoadNetwork) -> None:
    """With fraction 1 each edge is one arc and mid-block nodes have one arc in and one out."""
    roads = one_way_roads(grid, 1.0, np.random.default_rng(1))
    adj = roads.adjacency
    assert adj.nnz == grid.n_edges and roads.one_way.all()
    mid = np.flatnonzero(grid.degree == 2)
    out_deg = np.diff(adj.indptr)
    in_deg = np.bincount(adj.indices, minlength=grid.n_nodes)
    assert np.all(out_deg[mid] == 1) and np.all(in_deg[mid] == 1)


def test_routes_follow_arcs_and_are_shortest(grid: RoadNetwork) -> None:
    """Paths between reachable nodes use only arcs and have the directed shortest length."""
    roads = one_way_roads(grid, 0.6, np.random.default_rng(2))
    rng = np.random.default_rng(3)
    dist = csgraph.dijkstra(roads.adjacency, directed=True, indices=roads.reachable[:5])
    for i, s in enumerate(roads.reachable[:5].tolist()):
        t = int(rng.choice(roads.reachable))
        path = roads.path(s, t)
        assert path[0] == s and path[-1] == t
        hops = np.asarray(roads.adjacency[path[:-1], path[1:]]).reshape(-1)
        assert np.all(hops > 0)
        assert hops.sum() == pytest.approx(dist[i, t])


def test_one_way_traces_stay_in_the_reachable_part(grid: RoadNetwork) -> None:
    """Taxi traces with one-way streets repeat for a seed and differ from two-way traffic."""
    model = TaxiModel(one_way_fraction=0.5)
    a = taxi_traces(grid, 3, 600.0, 5.0, np.random.default_rng(4), model)
    b = taxi_traces(grid, 3, 600.0, 5.0, np.random.default_rng(4), model)
    two = taxi_traces(grid, 3, 600.0, 5.0, np.random.default_rng(4))
    np.testing.assert_array_equal(a.xy_m, b.xy_m)
    assert not np.array_equal(a.xy_m, two.xy_m)
