"""Road-distance blocks of the gated pairs: exact or capped at the limit, either source side."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.estimate.signatures import truncate_signature
from searchtrack.estimate.transport.road_blocks import (
    PairBlocks,
    chain_distances,
    road_distances,
    table_distances,
)
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


def _lattice(seed: int) -> RoadNetwork:
    """A small jittered lattice with streets removed: every node a junction, no chains."""
    rng = np.random.default_rng(seed)
    side = 7
    idx = np.arange(side * side).reshape(side, side)
    xy = np.stack(np.meshgrid(np.arange(side), np.arange(side), indexing="ij"), -1)
    xy = xy.reshape(-1, 2) * 10.0 + rng.normal(0.0, 1.5, (side * side, 2))
    pairs = np.vstack([np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()],
                       np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()]])
    pairs = pairs[rng.random(len(pairs)) >= 0.15]
    ell = np.linalg.norm(xy[pairs[:, 0]] - xy[pairs[:, 1]], axis=1)
    return RoadNetwork(xy, pairs, ell)


@pytest.mark.parametrize("seed", range(24))
def test_chain_distances_are_scipy_distances_within_the_limit(seed: int) -> None:
    """Through the chains' end junctions: SciPy's road distances where within the limit, inf
    beyond it (either at it, up to round-off) and across components, on random road maps
    (chains) and lattices (none)."""
    rng = np.random.default_rng([seed, 29])
    net = (random_network(int(rng.integers(3, 12)), float(rng.uniform(100.0, 600.0)),
                          seed=seed) if seed % 3 else _lattice(seed))
    metric = RoadMetric(net, dense_junction_limit=0)
    dist = net.shortest_paths(np.arange(net.n_nodes))
    sources = rng.choice(net.n_nodes, int(rng.integers(1, min(net.n_nodes, 15) + 1)),
                         replace=False)
    targets = rng.choice(net.n_nodes, int(rng.integers(1, min(net.n_nodes, 25) + 1)),
                         replace=False)
    want = dist[np.ix_(sources, targets)]
    for limit in (math.inf, float(np.quantile(want, 0.5)), float(np.quantile(want, 0.1))):
        got = chain_distances(metric, sources, targets, limit)
        near, far = want <= limit * (1.0 - 1e-12), want > limit * (1.0 + 1e-12)
        np.testing.assert_allclose(got[near], want[near], rtol=1e-12, atol=1e-9)
        assert np.isinf(got[far]).all()
        edge = ~near & ~far  # at the limit up to round-off: either
        assert (np.isinf(got[edge]) | np.isclose(got[edge], want[edge], rtol=1e-12)).all()


def test_chain_distances_across_components_and_along_a_chain() -> None:
    """Two nodes of one chain are as far apart as along it; another component is at inf."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [30.0, 0.0], [0.0, 50.0],
                       [10.0, 50.0]])
    net = RoadNetwork(coords, np.array([[0, 1], [1, 2], [2, 3], [4, 5]]),
                      np.array([10.0, 10.0, 10.0, 10.0]))
    got = chain_distances(RoadMetric(net, dense_junction_limit=0), np.array([1, 4]),
                          np.array([2, 3, 5]))
    np.testing.assert_array_equal(got, [[10.0, 20.0, math.inf], [math.inf, math.inf, 10.0]])


@pytest.mark.parametrize("seed", range(16))
def test_table_distances_are_the_metrics_bit_for_bit(seed: int) -> None:
    """The kernel pass over the junction table gives RoadMetric.distances exactly (same sums,
    same order), inf across components included, and SciPy's distances to round-off."""
    rng = np.random.default_rng([seed, 53])
    net = random_network(int(rng.integers(3, 12)), float(rng.uniform(100.0, 600.0)), seed=seed)
    metric = RoadMetric(net)
    assert metric.junction_distances is not None
    sources = rng.choice(net.n_nodes, int(rng.integers(1, min(net.n_nodes, 15) + 1)),
                         replace=False)
    targets = rng.choice(net.n_nodes, int(rng.integers(1, min(net.n_nodes, 40) + 1)))
    got = table_distances(metric, sources, targets)
    np.testing.assert_array_equal(got, metric.distances(sources, targets))
    want = net.shortest_paths(np.unique(targets))[:, sources].T
    cols = np.searchsorted(np.unique(targets), targets)
    np.testing.assert_allclose(got, want[:, cols], rtol=1e-12, atol=1e-9)
