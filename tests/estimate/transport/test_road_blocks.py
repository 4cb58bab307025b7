"""Road-distance blocks of the gated pairs: exact or capped at the limit, either source side."""

from __future__ import annotations

import math

import numpy as np

from searchtrack.estimate.signatures import truncate_signature
from searchtrack.estimate.transport.road_blocks import PairBlocks, road_distances
from searchtrack.models import RoadNetwork, random_network
from searchtrack.models.road_metric import RoadMetric


def _scene(seed: int) -> tuple[RoadNetwork, list, list, np.ndarray]:  # type: ignore[type-arg]
    net = random_network(9, 500.0, seed=seed)
    rng = np.random.default_rng(seed)
    sig_t = [truncate_signature(rng.random(net.n_nodes) * (rng.random(net.n_nodes) < d))
             for d in (0.05, 0.3, 0.1)]
    sig_q = [truncate_signature(rng.random(net.n_nodes) * (rng.random(net.n_nodes) < d))
             for d in (0.02, 0.2)]
    return net, sig_t, sig_q, np.array([[0, 0], [1, 0], [2, 1], [1, 1]])


def test_blocks_are_scipy_distances_or_capped_beyond_the_limit() -> None:
    """Finite entries are exact; entries beyond the limit read inf, and capped() puts the limit
    there; exact() gives the whole block."""
    net, sig_t, sig_q, pairs = _scene(3)
    dist = net.shortest_paths(np.arange(net.n_nodes))
    blocks = PairBlocks(RoadMetric(net, dense_junction_limit=0), sig_t, sig_q, pairs,
                        limit=150.0)
    for i, j in pairs:
        want = dist[np.ix_(sig_t[i].nodes, sig_q[j].nodes)]
        got = blocks.block(int(i), int(j))
        near = want <= 150.0
        np.testing.assert_allclose(got[near], want[near], rtol=1e-12)
        assert np.isinf(got[~near]).all()
        capped = blocks.capped(got)
        if (~near).any():
            assert capped is not None
            np.testing.assert_array_equal(capped[1], ~near)
            assert (capped[0][~near] == 150.0).all()
        else:
            assert capped is None
        np.testing.assert_allclose(blocks.exact(int(i), int(j)), want, rtol=1e-12)


def test_either_side_is_the_source_and_inf_limit_is_exact() -> None:
    """Swapping trackers and measurements transposes the blocks; with no limit nothing is
    capped."""
    net, sig_t, sig_q, pairs = _scene(5)
    metric = RoadMetric(net, dense_junction_limit=0)
    forward = PairBlocks(metric, sig_t, sig_q, pairs)
    backward = PairBlocks(metric, sig_q, sig_t, pairs[:, ::-1])
    assert forward.from_measurements != backward.from_measurements
    for i, j in pairs:
        block = forward.block(int(i), int(j))
        assert forward.capped(block) is None and np.isfinite(block).all()
        np.testing.assert_allclose(backward.block(int(j), int(i)).T, block, rtol=1e-12)


def test_road_distances_across_components_are_inf() -> None:
    """Nodes in another component are never reached."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 50.0], [10.0, 50.0]])
    net = RoadNetwork(coords, np.array([[0, 1], [2, 3]]), np.array([10.0, 10.0]))
    got = road_distances(net, np.array([0]), np.array([1, 3]))
    assert got[0, 0] == 10.0 and math.isinf(got[0, 1])


def test_a_junction_table_gives_the_same_blocks_uncapped() -> None:
    """With all junction distances precomputed the blocks are read from them, never capped."""
    net, sig_t, sig_q, pairs = _scene(7)
    table = PairBlocks(RoadMetric(net), sig_t, sig_q, pairs, limit=100.0)
    graph = PairBlocks(RoadMetric(net, dense_junction_limit=0), sig_t, sig_q, pairs)
    assert table.indexed and not graph.indexed and table.limit == math.inf
    for i, j in pairs:
        np.testing.assert_allclose(table.block(int(i), int(j)), graph.block(int(i), int(j)),
                                   rtol=1e-12)
