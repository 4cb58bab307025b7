"""Lemma 1 of paper 000 (Moore et al. 2021, §5.1): how long an ideal UAV takes to visit all targets.

The targets are on average ``S_point`` apart along the roads (Assumption 4); the shortest round trip
through ``M`` of them is taken as the mean perimeter of the regular ``M``-gons whose vertex pairs
``m`` sides apart are ``S_point`` apart, Eq. 30, flown at the UAV's speed, Eq. 31. Assumption 5
replaces ``S_point`` with the mean shortest-path distance between road nodes, ``S_node``;
:func:`point_distance_mc` estimates ``S_point`` itself so that the assumption can be checked.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import csgraph

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import check_stop
from searchtrack.models.roads import RoadNetwork

#: Most Dijkstra sources per block in :func:`s_node` (bounds the memory to ``block × N``
#: distances).
SOURCE_BLOCK = 256

#: Most distances one block of :func:`s_node` computes (fewer sources per block on a large map,
#: so that a stop request is seen between blocks within a fraction of a second).
BLOCK_DISTANCES = 2**21


def _connected(network: RoadNetwork) -> None:
    if not network.is_connected:
        raise InvalidInputError("network", network, "must be connected (distances would be inf); "
                                "use network.largest_component()")


def s_node(network: RoadNetwork, *, include_diagonal: bool = True,
           sources: int | None = None, seed: int | np.random.Generator = 0) -> float:
    """Mean all-pairs shortest-path distance between road nodes, ``S_node`` (m), §5.1.

    Dijkstra runs from every node (or from ``sources`` nodes drawn without replacement, an unbiased
    estimate for large maps), in blocks so that memory stays ``O(block · N)``.

    Parameters
    ----------
    network
        A connected road network; its nodes are the nodes averaged over.
    include_diagonal
        Average the full ``N × N`` matrix, zero diagonal included (the mean distance between two
        nodes drawn independently); otherwise the ``N (N − 1)`` ordered pairs of distinct nodes.
        On the 3 × 3 grid with 100 m blocks these give 177.78 m and 200.00 m.
    sources
        Number of source nodes to sample; ``None`` (or ``≥ N``) uses every node.
    seed
        Seed or generator for the sample of sources.

    Returns
    -------
    The mean distance in metres.

    Raises
    ------
    InvalidInputError
        If the network is not connected or ``sources`` is not a positive integer.
    StopRequested
        On a stop request inside :func:`~searchtrack.core.interrupt.stops_raise` (seen between
        blocks).
    """
    _connected(network)
    n = network.n_nodes
    if sources is None or checks.count("sources", sources, 1) >= n:
        src = np.arange(n)
    else:
        src = np.sort(np.random.default_rng(seed).choice(n, size=sources, replace=False))
    total = 0.0
    size = max(1, min(SOURCE_BLOCK, BLOCK_DISTANCES // n))
    for start in range(0, src.size, size):
        check_stop()
        block = src[start:start + size]
        dist = csgraph.dijkstra(network.adjacency, directed=False, indices=block)
        total += float(np.sum(dist))
    pairs = src.size * n if include_diagonal else src.size * (n - 1)
    return total / pairs


def sample_points(network: RoadNetwork, size: int, rng: np.random.Generator
                  ) -> tuple[NDArray[np.int64], NDArray[np.float64]]:
    """``size`` points uniform over the road length (Assumption 4): edge index and arc length (m)
    from the edge's first node ``edges[k, 0]``."""
    share = network.lengths_m / network.total_length_m
    edge = rng.choice(network.n_edges, size=size, p=share).astype(np.int64)
    offset = rng.uniform(0.0, 1.0, size=size) * network.lengths_m[edge]
    return edge, offset


def point_distance_mc(network: RoadNetwork, samples: int = 1000,
                      seed: int | np.random.Generator = 0) -> float:
    """Monte Carlo mean road distance between two points drawn uniformly on the roads,
    ``S_point`` (m), the quantity Assumption 5 equates with ``S_node`` (§5.1).

    Two points on the same edge are ``|s₁ − s₂|`` apart unless a way round is shorter; otherwise
    the distance is the least, over the end nodes ``a`` of the first edge and ``b`` of the
    second, of the distance from the point to ``a``, the node distance ``a → b`` and from ``b``
    to the point.

    Parameters
    ----------
    network
        A connected road network.
    samples
        Number of point pairs, ≥ 1.
    seed
        Seed or generator (the estimate is deterministic for a seed).
    """
    _connected(network)
    count = checks.count("samples", samples, 1)
    rng = np.random.default_rng(seed)
    e1, s1 = sample_points(network, count, rng)
    e2, s2 = sample_points(network, count, rng)
    ends1, ends2 = network.edges[e1], network.edges[e2]
    nodes, inverse = np.unique(ends1, return_inverse=True)
    dist = csgraph.dijkstra(network.adjacency, directed=False, indices=nodes)
    row = inverse.reshape(count, 2)
    len1, len2 = network.lengths_m[e1], network.lengths_m[e2]
    to_end1 = np.stack([s1, len1 - s1], axis=1)          # point 1 to node a ∈ {first, second}
    from_end2 = np.stack([s2, len2 - s2], axis=1)        # node b ∈ {first, second} to point 2
    best = np.full(count, math.inf)
    for a in range(2):
        for b in range(2):
            via = to_end1[:, a] + dist[row[:, a], ends2[:, b]] + from_end2[:, b]
            best = np.minimum(best, via)
    same = e1 == e2
    best[same] = np.minimum(best[same], np.abs(s1[same] - s2[same]))
    return float(best.mean())


def round_trip_ratio(targets: int) -> float:
    """``S_avg(M) / S_point`` of Eq. 30: ``M/(M−1) Σ_{m=1}^{M−1} sin(π/M)/sin(πm/M)``.

    2, 3, 3.6095, 4.0451 and 5.3047 for ``M`` = 2, 3, 4, 5 and 10. Eq. 30 is the mean perimeter
    of the round trip, not a side length.

    Raises
    ------
    InvalidInputError
        Unless ``targets`` is an integer ≥ 2 (a round trip needs two targets).
    """
    m_targets = checks.count("targets", targets, 2)
    m = np.arange(1, m_targets)
    ratio = np.sin(np.pi / m_targets) / np.sin(np.pi * m / m_targets)
    return float(m_targets / (m_targets - 1) * ratio.sum())


def s_avg(targets: int, s_point_m: float) -> float:
    """Mean round-trip length through ``targets`` targets, ``S_avg(M)`` (m), Eq. 30."""
    return round_trip_ratio(targets) * checks.positive("s_point_m", s_point_m)


def t_ave(targets: int, s_point_m: float, uav_speed_mps: float) -> float:
    """Mean minimum round-trip time through all targets, ``T_ave(M) = S_avg(M)/V_a`` (s), Eq. 31."""
    return s_avg(targets, s_point_m) / checks.positive("uav_speed_mps", uav_speed_mps)
