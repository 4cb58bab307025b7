"""Road networks from polylines: junctions merged, roads resampled evenly, parallel roads pruned."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import LocalProjection, network_from_polylines


def test_builder_merges_shared_ends_and_keeps_shortest_parallel_road() -> None:
    """Roads ending at equal coordinates share a junction; of parallel roads the shortest stays."""
    net = network_from_polylines(
        [
            [[0, 0], [5, 0]],  # 5 m, one piece
            [[0.0, 0.0], [2.5, 1.0], [5.0, 0.0]],  # 5.39 m, one piece parallel to it: dropped
            [[5, 0], [0, 0]],  # the first road again, reversed: dropped
            [[0, 0], [0, 4], [5, 0]],  # 10.40 m: two pieces, through a new interior node
            [[5, 0], [9, 0]],  # 4 m
        ],
        spacing_m=10.0,
        largest_component=False,
    )
    assert net.n_nodes == 3 + 1 and net.n_edges == 4
    half = (4 + math.hypot(5, 4)) / 2
    assert sorted(net.lengths_m) == pytest.approx(sorted([5.0, 4.0, half, half]))


def test_builder_closed_loop_gets_three_pieces() -> None:
    """A loop road shorter than the spacing still becomes a triangle, not a self-loop."""
    net = network_from_polylines([[[0, 0], [3, 0], [3, 3], [0, 0]]], spacing_m=100.0)
    assert net.n_nodes == 3 and net.n_edges == 3


def test_polylines_of_zero_length() -> None:
    """Polylines that do not move give no network."""
    with pytest.raises(InvalidInputError, match="positive length"):
        network_from_polylines([[[1.0, 1.0], [1.0, 1.0]]])


def test_straight_road_is_cut_into_equal_pieces() -> None:
    """A 25 m road at 10 m spacing is cut into ⌈2.5⌉ = 3 pieces of 8.33 m; 20 m into exactly 2."""
    net = network_from_polylines([[[0.0, 0.0], [25.0, 0.0]]], spacing_m=10.0)
    np.testing.assert_allclose(net.coords, [[0.0, 0.0], [25.0, 0.0], [25 / 3, 0.0],
                                            [50 / 3, 0.0]], atol=1e-12)
    np.testing.assert_allclose(net.lengths_m, 25 / 3)
    assert network_from_polylines([[[0.0, 0.0], [20.0, 0.0]]], spacing_m=10.0).n_edges == 2


def test_interior_nodes_follow_the_polyline() -> None:
    """Along an L of 10 m + 10 m at 5 m spacing, the nodes sit on the bend, not on the chord."""
    net = network_from_polylines([[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]]], spacing_m=5.0)
    np.testing.assert_allclose(net.coords[2:], [[5.0, 0.0], [10.0, 0.0], [10.0, 5.0]],
                               atol=1e-12)
    np.testing.assert_allclose(net.lengths_m, 5.0)


def test_repeated_points_are_dropped() -> None:
    """A polyline that repeats a point is the same road as without the repeat."""
    a = network_from_polylines([[[0.0, 0.0], [0.0, 0.0], [10.0, 0.0], [10.0, 0.0]]], 4.0)
    b = network_from_polylines([[[0.0, 0.0], [10.0, 0.0]]], 4.0)
    np.testing.assert_array_equal(a.coords, b.coords)
    np.testing.assert_array_equal(a.edges, b.edges)


def test_interior_points_never_join_other_roads() -> None:
    """Two roads crossing at their midpoints stay apart: only ends make junctions."""
    net = network_from_polylines([[[0.0, 0.0], [10.0, 0.0]], [[5.0, -5.0], [5.0, 5.0]]], 5.0,
                                 largest_component=False)
    assert net.n_components == 2 and net.n_nodes == 6


def test_largest_component_and_metadata() -> None:
    """By default only the largest component stays; source and projection are stored."""
    roads = [[[0.0, 0.0], [30.0, 0.0]], [[100.0, 100.0], [110.0, 100.0]]]
    proj = LocalProjection(0.5, 0.5)
    net = network_from_polylines(roads, 10.0, source="two roads", projection=proj)
    assert net.n_nodes == 4 and net.is_connected
    assert net.source == "two roads" and net.projection is proj and net.spacing_m == 10.0
    assert network_from_polylines(roads, 10.0, largest_component=False).n_components == 2


@pytest.mark.parametrize(("polylines", "field"), [
    ([], "polylines"),
    ([[[0.0, 0.0]]], "polylines[0]"),
    ([[[0.0, 0.0], [1.0, 1.0]], [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]], "polylines[1]"),
    ([[[0.0, 0.0], [math.nan, 1.0]]], "polylines[0]"),
])
def test_malformed_polylines_are_named(polylines: list[list[list[float]]], field: str) -> None:
    """No polylines, a single point, 3-D points and NaN are refused, naming the polyline."""
    with pytest.raises(InvalidInputError) as err:
        network_from_polylines(polylines)
    assert err.value.field == field
