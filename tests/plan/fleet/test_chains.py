"""Directed chains and subdivisions of a road map (paper 000, §5.3, Fig. 6)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models import RoadNetwork, random_network
from searchtrack.plan.fleet import chain_graph, subdivisions

from .conftest import grid_3x3, irregular


def _check_chains(roads: RoadNetwork) -> None:
    graph = chain_graph(roads)
    assert graph.length_m.sum() == pytest.approx(2 * roads.total_length_m)
    assert graph.share.sum() == pytest.approx(1.0)
    assert np.all(graph.fanout >= 1)
    for c in range(graph.n_chains):
        assert np.all(roads.degree[graph.path(c)[1:-1]] == 2)   # through degree-2 nodes only
    assert np.all(roads.degree[np.concatenate([graph.tail, graph.head])] != 2)
    for c in range(graph.n_chains):
        path = graph.path(c)
        for child in graph.children(c):
            child_path = graph.path(child)
            assert child_path[0] == path[-1]              # children leave the head
            if graph.fanout[c] > 1:                       # no U-turn unless forced
                assert child_path[1] != path[-2]


@pytest.mark.parametrize("spacing_m", [100.0, 10.0, 7.0])
def test_three_by_three_gives_the_papers_three_subdivisions(spacing_m: float) -> None:
    """16 directed chains in 3 subdivisions: corner paths (2ℓ, 4/6, {corner, inward spoke}),
    inward spokes (ℓ, 1/6, 3 outward spokes), outward spokes (ℓ, 1/6, 2 corner paths),
    whatever the resampling of the roads."""
    graph = chain_graph(grid_3x3(spacing_m=spacing_m))
    assert graph.n_chains == 16
    corner, inward, outward = subdivisions(graph)
    assert (corner.length_m, corner.share, len(corner.members)) == pytest.approx((200, 4 / 6, 8))
    assert (inward.length_m, inward.share, len(inward.members)) == pytest.approx((100, 1 / 6, 4))
    assert (outward.length_m, outward.share, len(outward.members)) == pytest.approx(
        (100, 1 / 6, 4))
    assert corner.children == (0, 1)
    assert inward.children == (2, 2, 2)
    assert outward.children == (0, 0)
    assert [s.fanout for s in (corner, inward, outward)] == [2, 3, 2]


def test_chains_are_consistent_on_any_map() -> None:
    """Chains cover each directed road once, pass only degree-2 nodes and never U-turn except
    at a dead end, on grids, a hand-made map and random networks."""
    for roads in (grid_3x3(), irregular(), random_network(15, 800.0, 40.0, seed=2),
                  random_network(30, 1500.0, 25.0, seed=5)):
        _check_chains(roads)


def test_dead_end_turns_back() -> None:
    """On a single road the only chains are its two directions, each the other's child."""
    roads = RoadNetwork(np.array([[0.0, 0.0], [50.0, 0.0], [80.0, 0.0]]),
                        np.array([[0, 1], [1, 2]]), np.array([50.0, 30.0]))
    graph = chain_graph(roads)
    assert graph.n_chains == 2
    assert graph.length_m.tolist() == [80.0, 80.0]
    assert graph.children(0).tolist() == [1] and graph.children(1).tolist() == [0]
    (both,) = subdivisions(graph)
    assert both.share == 1.0 and both.children == (0,)


def test_loop_without_junctions_is_cut() -> None:
    """A ring road of degree-2 nodes gives two chains (one per direction), each its own child."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]])
    roads = RoadNetwork(coords, np.array([[0, 1], [1, 2], [2, 3], [0, 3]]),
                        np.array([10.0, 10.0, 10.0, 10.0]))
    graph = chain_graph(roads)
    assert graph.n_chains == 2
    assert graph.length_m.tolist() == [40.0, 40.0]
    assert [graph.children(c).tolist() for c in range(2)] == [[0], [1]]


def test_ungrouped_subdivisions_are_single_chains() -> None:
    """With grouping off every chain is its own subdivision; shares still sum to 1."""
    graph = chain_graph(irregular())
    subs = subdivisions(graph, grouped=False)
    assert len(subs) == graph.n_chains
    assert sum(s.share for s in subs) == pytest.approx(1.0)
    assert sorted(m for s in subs for m in s.members) == list(range(graph.n_chains))


def test_grouping_respects_the_exit_structure() -> None:
    """Grouped chains share a length and the multiset of their children's groups; the two
    directions of the irregular map's short dead-end road are equally long but apart."""
    graph = chain_graph(irregular())
    subs = subdivisions(graph)
    group = np.empty(graph.n_chains, dtype=np.int64)
    for g, sub in enumerate(subs):
        group[list(sub.members)] = g
    for sub in subs:
        assert np.ptp(graph.length_m[list(sub.members)]) < 1e-6
        for c in sub.members:
            assert tuple(sorted(group[graph.children(c)].tolist())) == sub.children
    into, out_of = (int(np.flatnonzero((graph.tail == a) & (graph.head == b))[0])
                    for a, b in ((2, 5), (5, 2)))
    assert graph.length_m[into] == graph.length_m[out_of]
    assert group[into] != group[out_of]
