"""Road distances through the chain decomposition equal Dijkstra on the road graph."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import RoadNetwork, grid_network, random_network
from searchtrack.models.road_metric import RoadMetric

ATOL = 1e-9


def odd_network() -> RoadNetwork:
    """Every chain shape at once, on 17 nodes in three components.

    Component 1: junctions 0 and 3 joined by a direct edge, a one-node chain (via 1), a long
    parallel chain (4-5-6) and a loop chain back to 3 (7-8); a dead end 9 hangs off 0.
    Component 2: a bare cycle 10-11-12-13. Component 3: the path 14-15-16.
    """
    rng = np.random.default_rng(3)
    coords = rng.uniform(0.0, 50.0, size=(17, 2))
    edges = [(0, 3), (0, 1), (1, 3), (0, 4), (4, 5), (5, 6), (6, 3), (3, 7), (7, 8), (8, 3),
             (0, 9), (10, 11), (11, 12), (12, 13), (10, 13), (14, 15), (15, 16)]
    e = np.array(edges)
    straight = np.linalg.norm(coords[e[:, 0]] - coords[e[:, 1]], axis=1)
    lengths = straight + rng.uniform(1.0, 30.0, size=len(edges))
    return RoadNetwork(coords, e, lengths, source="odd")


def _check_all_pairs(metric: RoadMetric) -> None:
    net = metric.network
    nodes = np.arange(net.n_nodes)
    np.testing.assert_allclose(metric.distances(nodes, nodes), net.shortest_paths(nodes),
                               rtol=1e-12, atol=ATOL)


@pytest.mark.parametrize("limit", [3000, 0])
def test_odd_shapes_match_dijkstra(limit: int) -> None:
    """Parallel, one-node, loop and dead-end chains, a bare cycle and components: exact."""
    _check_all_pairs(RoadMetric(odd_network(), dense_junction_limit=limit))


@pytest.mark.parametrize("limit", [3000, 0])
def test_grid_matches_dijkstra(limit: int) -> None:
    """On a 3×4 grid of 100 m blocks, every node pair."""
    _check_all_pairs(RoadMetric(grid_network(3, 4), dense_junction_limit=limit))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_random_network_matches_dijkstra(seed: int) -> None:
    """Random planar roads, every node pair; the junctions are the nodes of degree ≠ 2."""
    net = random_network(10, 400.0, seed=seed)
    metric = RoadMetric(net)
    np.testing.assert_array_equal(metric.junctions, np.flatnonzero(net.degree != 2))
    _check_all_pairs(metric)


def test_subsets_and_among_select_rows() -> None:
    """``from_nodes(...).to(targets, among)`` returns the rows of the chosen sources."""
    net = grid_network(2, 3)
    metric = RoadMetric(net, dense_junction_limit=0)
    src, tgt = np.array([5, 1, 17]), np.array([0, 9, 3, 3])
    full = net.shortest_paths(src)[:, tgt]
    rows = metric.from_nodes(src)
    np.testing.assert_allclose(rows.to(tgt), full, atol=ATOL)
    np.testing.assert_allclose(rows.to(tgt, [2, 0]), full[[2, 0]], atol=ATOL)
    assert metric.distances(src, np.empty(0, dtype=np.int64)).shape == (3, 0)


def test_components_are_infinitely_far() -> None:
    """Distances across components are inf and components are labelled."""
    metric = RoadMetric(odd_network())
    assert np.isinf(metric.distances([0], [10, 14])).all()
    assert len(set(metric.component[[0, 10, 14]].tolist())) == 3


def test_lower_bound_factor_bounds_road_distance() -> None:
    """κ = 1 when edges are at least straight; an edge shorter than its chord lowers κ, and
    road distance ≥ κ × straight line holds for every pair."""
    assert RoadMetric(grid_network(2, 2)).lower_bound_factor == pytest.approx(1.0)
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [20.0, 10.0]])
    edges = np.array([[0, 1], [1, 2], [2, 3], [0, 3]])
    net = RoadNetwork(coords, edges, np.array([10.0, 10.0, 10.0, 5.0]))
    metric = RoadMetric(net)
    assert metric.lower_bound_factor == pytest.approx(5.0 / np.hypot(20.0, 10.0))
    nodes = np.arange(4)
    straight = np.linalg.norm(coords[:, None] - coords[None], axis=2)
    assert (metric.distances(nodes, nodes) >= metric.lower_bound_factor * straight - 1e-12).all()


def test_derived_arrays_are_read_only() -> None:
    """The metric is immutable: frozen fields and read-only arrays."""
    metric = RoadMetric(grid_network(2, 2))
    with pytest.raises(dataclasses.FrozenInstanceError):
        metric.network = grid_network(2, 3)  # type: ignore[misc]
    with pytest.raises(ValueError, match="read-only"):
        metric.off_a[0] = 1.0


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"network": "roads"}, "network"),
    ({"dense_junction_limit": -1}, "dense_junction_limit"),
    ({"dense_junction_limit": True}, "dense_junction_limit"),
    ({"dense_junction_limit": 2.5}, "dense_junction_limit"),
])
def test_bad_construction(kwargs: dict[str, object], field: str) -> None:
    """A bad network or limit raises naming the field."""
    args: dict[str, object] = {"network": grid_network(2, 2), **kwargs}
    with pytest.raises(InvalidInputError) as err:
        RoadMetric(**args)  # type: ignore[arg-type]
    assert err.value.field == field


@pytest.mark.parametrize(("sources", "targets", "field"), [
    ([0, 99], [0], "sources"),
    ([0.5], [0], "sources"),
    ([[0]], [0], "sources"),
    ([0], [-1], "targets"),
])
def test_bad_nodes(sources: object, targets: object, field: str) -> None:
    """Node indices out of range, fractional or not 1-D raise naming the argument."""
    metric = RoadMetric(grid_network(2, 2, block_m=20.0))
    with pytest.raises(InvalidInputError) as err:
        metric.distances(sources, targets)  # type: ignore[arg-type]
    assert err.value.field == field
