"""The road graph: matrices (2.2)–(2.4), distances and paths, node look-ups, and validation."""

from __future__ import annotations

import math

import networkx as nx
import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, grid_network, random_network, read_osm
from tests.models.osm_data import TINY

# ----- graph matrices ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "make", [lambda: read_osm(TINY), lambda: grid_network(3, 4), lambda: random_network(30)]
)
def test_laplacian_rows_sum_to_zero_and_equal_b_bt(make: object) -> None:
    """L = D − A has zero row sums and equals B Bᵀ (unweighted); B diag(w) Bᵀ is weighted."""
    net: RoadNetwork = make()  # type: ignore[operator]
    lap, b = net.laplacian, net.incidence
    assert np.abs(lap.sum(axis=1)).max() == 0
    assert abs(lap - b @ b.T).max() == 0
    np.testing.assert_array_equal(lap.diagonal(), net.degree)
    unit = (net.adjacency > 0).astype(float)
    assert abs(lap - (np.diag(net.degree) - unit.toarray())).max() == 0
    w = 1.0 / net.lengths_m**2
    lw = net.weighted_laplacian(w)
    assert np.abs(lw.sum(axis=1)).max() < 1e-12
    u, v = net.edges[:, 0], net.edges[:, 1]
    np.testing.assert_allclose(lw[u, v], -w)
    np.testing.assert_array_equal(np.abs(b).sum(axis=0), 2)  # one +1 and one −1 per column


def test_networkx_view_matches() -> None:
    """to_networkx has the same nodes, edges and lengths, so its Dijkstra agrees with ours."""
    net = read_osm(TINY)
    g = net.to_networkx()
    assert g.number_of_nodes() == net.n_nodes and g.number_of_edges() == net.n_edges
    theirs = nx.single_source_dijkstra_path_length(g, 0, weight="length")
    ours = net.shortest_paths(0)[0]
    np.testing.assert_allclose([theirs[i] for i in range(net.n_nodes)], ours)
    assert g.nodes[0]["pos"] == tuple(net.coords[0])


# ----- distances and look-ups --------------------------------------------------------------------


def test_grid_shortest_paths_are_manhattan() -> None:
    """From any intersection, the road distance to every node is the Manhattan distance."""
    net = grid_network(4, 5, block_m=50.0, spacing_m=10.0)
    xy = net.coords
    corners = np.flatnonzero(np.all(np.isclose(xy % 50.0, 0.0), axis=1))
    assert corners.size == 20
    dist = net.shortest_paths(corners)
    manhattan = np.abs(xy[corners][:, None, :] - xy[None, :, :]).sum(axis=2)
    np.testing.assert_allclose(dist, manhattan, atol=1e-9)


def test_shortest_path_nodes_are_adjacent() -> None:
    """The path between opposite grid corners is Manhattan long and walks along edges."""
    net = grid_network(3, 3, block_m=100.0, spacing_m=20.0)
    start, end = net.nearest_nodes([[0.0, 0.0], [200.0, 200.0]])
    path, length = net.shortest_path(int(start), int(end))
    assert length == pytest.approx(400.0)
    assert path[0] == start and path[-1] == end
    steps = net.adjacency[path[:-1], path[1:]]
    assert np.all(steps > 0) and steps.sum() == pytest.approx(400.0)


def test_shortest_paths_limit() -> None:
    """Nodes beyond limit_m are reported unreachable (inf)."""
    net = grid_network(2, 5, block_m=100.0, spacing_m=10.0)
    dist = net.shortest_paths([0], limit_m=55.0)[0]
    assert np.isinf(dist).sum() > 0 and dist[np.isfinite(dist)].max() <= 55.0


def test_nodes_within_matches_brute_force(grid: RoadNetwork) -> None:
    """RoadNetwork.nodes_within returns exactly the nodes within the radius of each point."""
    xy = np.array([[100.0, 100.0], [0.0, 0.0], [500.0, 500.0]])
    point, node = grid.nodes_within(xy, [35.0, 20.0, 10.0])
    for k, r in enumerate((35.0, 20.0, 10.0)):
        want = np.flatnonzero(np.linalg.norm(grid.coords - xy[k], axis=1) <= r)
        np.testing.assert_array_equal(node[point == k], want)
    assert np.count_nonzero(point == 2) == 0


# ----- errors -----------------------------------------------------------------------------------


@pytest.mark.parametrize("spacing", [0.0, -1.0, math.nan, math.inf, True, "10"])
def test_bad_spacing(spacing: object) -> None:
    """Spacing must be a finite positive number, for the reader and the generators alike."""
    with pytest.raises(InvalidInputError, match="spacing_m"):
        read_osm(TINY, spacing)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="spacing_m"):
        grid_network(2, 2, spacing_m=spacing)  # type: ignore[arg-type]


def test_network_without_edges() -> None:
    """A RoadNetwork needs at least one edge."""
    with pytest.raises(InvalidInputError, match="edges"):
        RoadNetwork(
            coords=np.zeros((2, 2)), edges=np.empty((0, 2), dtype=np.int64), lengths_m=np.empty(0)
        )


@pytest.mark.parametrize(
    ("edges", "lengths", "field"),
    [
        ([[0, 0]], [1.0], "edges"),
        ([[0, 1], [1, 0]], [1.0, 1.0], "edges"),
        ([[0, 3]], [1.0], "edges"),
        ([[0, 1]], [0.0], "lengths_m"),
        ([[0, 1]], [math.nan], "lengths_m"),
    ],
)
def test_network_refuses_bad_edges(
    edges: list[list[int]], lengths: list[float], field: str
) -> None:
    """Self-loops, duplicates, unknown nodes and non-positive lengths are refused by name."""
    coords = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    with pytest.raises(InvalidInputError, match=field):
        RoadNetwork(coords=coords, edges=np.array(edges), lengths_m=np.array(lengths))


def test_bad_sources() -> None:
    """Shortest paths refuse node indices outside the network."""
    net = grid_network(2, 2)
    with pytest.raises(InvalidInputError, match="sources"):
        net.shortest_paths([net.n_nodes])
    with pytest.raises(InvalidInputError, match="limit_m"):
        net.shortest_paths([0], limit_m=math.nan)
