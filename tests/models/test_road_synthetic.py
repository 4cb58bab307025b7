"""Synthetic road networks: Manhattan grids counted by hand, seeded random planar roads."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import grid_network, random_network
from searchtrack.models.road_synthetic import grid_node


def test_grid_counts_by_hand() -> None:
    """A 3×4 grid of 100 m blocks at 10 m: 17 blocks, 165 nodes, 170 edges, 8 intersections."""
    net = grid_network(3, 4, block_m=100.0, spacing_m=10.0)
    blocks = 3 * 3 + 4 * 2
    assert net.n_nodes == 12 + 9 * blocks == 165
    assert net.n_edges == 10 * blocks == 170
    assert net.total_length_m == pytest.approx(1700.0)
    np.testing.assert_allclose(net.lengths_m, 10.0)
    assert net.n_intersections == 12 - 4  # corners have degree 2
    assert np.bincount(net.degree).tolist() == [0, 0, 4 + 9 * blocks, 6, 2]
    assert net.hull_area_m2 == pytest.approx(300.0 * 200.0)
    assert net.bbox_area_m2 == pytest.approx(300.0 * 200.0)
    assert net.intersection_density_per_km2 == pytest.approx(8 / 0.06)


def test_grid_spacing_not_dividing_block() -> None:
    """Blocks of 100 m at 30 m spacing are cut into 4 edges of 25 m."""
    net = grid_network(2, 2, block_m=100.0, spacing_m=30.0)
    assert net.n_nodes == 4 + 4 * 3 and net.n_edges == 16
    np.testing.assert_allclose(net.lengths_m, 25.0)


def test_random_network_is_seeded_connected_and_resampled() -> None:
    """The same seed gives the same network; it is connected and honours the spacing."""
    a = random_network(40, 800.0, 15.0, seed=7)
    b = random_network(40, 800.0, 15.0, seed=np.random.default_rng(7))
    c = random_network(40, 800.0, 15.0, seed=8)
    np.testing.assert_array_equal(a.coords, b.coords)
    np.testing.assert_array_equal(a.edges, b.edges)
    assert a.n_nodes != c.n_nodes or not np.array_equal(a.coords, c.coords)
    assert a.is_connected and a.lengths_m.max() <= 15.0 * (1 + 1e-9)
    tree = random_network(40, 800.0, 15.0, extra_road_fraction=0.0, seed=7)
    assert tree.n_edges == tree.n_nodes - 1  # the spanning tree alone


def test_single_row_grid_is_a_line() -> None:
    """A 1 × 3 grid is one 200 m road: 21 nodes, 20 edges, no intersections."""
    net = grid_network(1, 3, block_m=100.0, spacing_m=10.0)
    assert (net.n_nodes, net.n_edges, net.n_intersections) == (21, 20, 0)
    assert net.total_length_m == pytest.approx(200.0)
    assert net.source == "grid 1x3, block 100 m"


def test_full_triangulation_and_spanning_tree() -> None:
    """With every Delaunay edge kept a triangulation of n points with h on the hull has 3n − 3 − h
    roads; with none, the roads are the Euclidean minimum spanning tree."""
    from scipy.sparse.csgraph import minimum_spanning_tree
    from scipy.spatial import ConvexHull
    from scipy.spatial.distance import cdist

    full = random_network(25, 500.0, 1e4, extra_road_fraction=1.0, seed=3)
    hull = ConvexHull(full.coords).vertices.size
    assert full.n_nodes == 25 and full.n_edges == 3 * 25 - 3 - hull
    assert np.all((full.coords >= 0.0) & (full.coords <= 500.0))
    tree = random_network(25, 500.0, 1e4, extra_road_fraction=0.0, seed=3)
    mst = minimum_spanning_tree(cdist(tree.coords, tree.coords)).sum()
    assert tree.total_length_m == pytest.approx(mst, rel=1e-12)


@pytest.mark.parametrize(("make", "field"), [
    (lambda: grid_network(1, 1), "rows"),
    (lambda: grid_network(0, 3), "rows"),
    (lambda: grid_network(3, True), "cols"),
    (lambda: grid_network(3, 3, block_m=0.0), "block_m"),
    (lambda: random_network(2), "n_junctions"),
    (lambda: random_network(10, extent_m=-1.0), "extent_m"),
    (lambda: random_network(10, extra_road_fraction=1.5), "extra_road_fraction"),
    (lambda: random_network(10, spacing_m=math.inf), "spacing_m"),
])
def test_bad_arguments_are_named(make: object, field: str) -> None:
    """Too few intersections or junctions, non-positive sizes and bad fractions are named."""
    with pytest.raises(InvalidInputError) as err:
        make()  # type: ignore[operator]
    assert err.value.field == field


@pytest.mark.parametrize(("rows", "cols", "spacing"), [(2, 3, 50.0), (3, 2, 50.0), (1, 4, 30.0),
                                                       (4, 3, 100.0), (5, 2, 100.0 / 3.0)])
def test_grid_node_is_the_documented_numbering(rows: int, cols: int, spacing: float) -> None:
    """Junction ``(r, c)`` at ``(c·s, r·s)`` is node ``c·rows + r`` on grids that are not square,
    with roads of one block or resampled inside the blocks."""
    for step in (spacing, spacing / 4.0):
        net = grid_network(rows, cols, block_m=spacing, spacing_m=step)
        for r in range(rows):
            for c in range(cols):
                node = grid_node(rows, cols, r, c)
                assert node == c * rows + r
                assert np.allclose(net.coords[node], [c * spacing, r * spacing])
    with pytest.raises(InvalidInputError):
        grid_node(rows, cols, rows, 0)
