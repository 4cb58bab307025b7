"""Merging chains of degree-2 nodes: the merged network, the exact position map, motion
equivalence along a chain, and the splitting of parallel chains and loops."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.road_search import ChainGraph


def node_at(coords: np.ndarray, xy: tuple[float, float]) -> int:
    return int(np.flatnonzero(np.all(np.isclose(coords, xy), axis=1))[0])


def test_merged_grid_has_the_papers_sixteen_edges() -> None:
    """The 3×3 grid at 10 m merges into 5 intersections and 16 directed edges (the paper's
    count): 4 spokes and 4 corner roads of 200 m, each both ways; the length is kept."""
    net = grid_network(3, 3, 100.0, spacing_m=10.0)
    chains = ChainGraph(net)
    assert chains.roads.n_edges == 16 and chains.network.n_nodes == 5
    assert sorted(chains.network.lengths_m.round(6)) == [100.0] * 4 + [200.0] * 4
    assert chains.network.total_length_m == pytest.approx(net.total_length_m)
    assert np.all(chains.coarse_of_node[chains.node_ids] == np.arange(5))
    assert np.sum(chains.coarse_of_node >= 0) == 5


def test_positions_map_exactly_on_straight_chains() -> None:
    """With the corners kept every merged road is straight: G(x) is unchanged by the map, and
    offsets plus lengths never pass the merged edge's end."""
    net = grid_network(3, 3, 100.0, spacing_m=10.0)
    corners = tuple(node_at(net.coords, xy) for xy in ((0, 0), (0, 200), (200, 0), (200, 200)))
    chains = ChainGraph(net, keep=corners)
    fine = DirectedRoads(net)
    e, s = fine.uniform(400, np.random.default_rng(0))
    ce, cs = chains.to_coarse(e, s)
    assert np.allclose(fine.point(e, s), chains.roads.point(ce, cs))
    ends = chains.offset_m + fine.length
    assert np.all(ends <= chains.roads.length[chains.edge_map] + 1e-9)
    assert np.all(chains.roads.tail[chains.edge_map[0::2]] >= 0)


def test_motion_along_a_chain_is_the_same() -> None:
    """Advancing along a chain without reaching its end gives the same place on both maps
    (degree-2 nodes have one successor: no random turn)."""
    net = grid_network(3, 3, 100.0, spacing_m=10.0)
    chains = ChainGraph(net)
    fine = DirectedRoads(net)
    rng = np.random.default_rng(1)
    e, s = fine.uniform(300, rng)
    ce, cs = chains.to_coarse(e, s)
    room = chains.roads.length[ce] - cs
    step = rng.uniform(0.0, 1.0, 300) * room * 0.999
    fe, fs = fine.advance(e, s, step, rng)
    me, ms = chains.to_coarse(fe, fs)
    assert np.array_equal(me, ce)
    assert np.allclose(ms, cs + step)


def test_parallel_chains_and_loops_keep_interior_nodes() -> None:
    """Three roads between the same two junctions and a loop stay a simple network: interior
    nodes are kept so that no edge is doubled and none is a self-loop."""
    a, b = (0.0, 0.0), (100.0, 0.0)
    polylines = [np.array([a, b]), np.array([a, (50.0, 60.0), b]),
                 np.array([a, (50.0, -60.0), b]),
                 np.array([b, (160.0, 0.0), (160.0, 60.0), b]),  # a loop at b
                 np.array([a, (-80.0, 0.0)])]
    net = network_from_polylines(polylines, 10.0)
    chains = ChainGraph(net)
    coarse = chains.network
    ends = int(np.sum(net.degree != 2))  # a, b and the dead end
    assert ends == 3 and coarse.n_nodes == ends + 2 + 2  # one per extra parallel, two per loop
    assert coarse.total_length_m == pytest.approx(net.total_length_m)
    assert coarse.n_edges == np.unique(coarse.edges, axis=0).shape[0]
    assert np.all(coarse.edges[:, 0] != coarse.edges[:, 1])
    # Every fine directed edge lies inside its merged edge.
    fine = DirectedRoads(net)
    assert np.all(chains.offset_m >= -1e-9)
    assert np.all(chains.offset_m + fine.length <= chains.roads.length[chains.edge_map] + 1e-9)
    # The merged paths cover every fine edge once.
    covered: list[tuple[int, int]] = []
    index = {(int(p), int(q)): k for k, (p, q) in enumerate(net.edges)}
    for k, (u, v) in enumerate(coarse.edges):
        path = chains.fine_path([int(u), int(v)]).tolist()
        assert path[0] == chains.node_ids[u] and path[-1] == chains.node_ids[v]
        pieces = [(min(p, q), max(p, q)) for p, q in itertools.pairwise(path)]
        total = sum(net.lengths_m[index[piece]] for piece in pieces)
        assert total == pytest.approx(coarse.lengths_m[k], rel=1e-12)
        covered += pieces
    assert sorted(covered) == sorted(map(tuple, net.edges.tolist()))


def test_fine_path_of_a_route_and_errors() -> None:
    """A route of merged nodes expands to every fine node; non-adjacent nodes and bad keeps
    are refused."""
    net = grid_network(3, 3, 100.0, spacing_m=10.0)
    chains = ChainGraph(net)
    centre = int(chains.coarse_of_node[node_at(net.coords, (100, 100))])
    west = int(chains.coarse_of_node[node_at(net.coords, (0, 100))])
    path = chains.fine_path([centre, west, centre])
    assert path.size == 21 and path[0] == path[-1] == chains.node_ids[centre]
    others = [v for v in range(5) if v not in (centre, west)]
    far = next(v for v in others
               if not np.any((chains.network.edges == sorted((west, v))).all(axis=1)))
    with pytest.raises(ValueError, match="not adjacent"):
        chains.fine_path([west, far])
    with pytest.raises(InvalidInputError) as err:
        ChainGraph(net, keep=(net.n_nodes,))
    assert err.value.field == "keep"
