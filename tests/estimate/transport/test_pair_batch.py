"""All pairs of a source signature in one kernel call: the per-pair path and the LP to 1e-9."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.estimate.emd_matrix import _TransportPairs
from searchtrack.estimate.signatures import SLACK, centroid_bound, truncate_rows
from searchtrack.estimate.transport import emd
from searchtrack.estimate.transport.pair_batch import (
    FALLBACK,
    SOLVED,
    packed,
    solve_pair,
    solve_sources,
)
from searchtrack.models import RoadNetwork, random_network
from searchtrack.models.road_metric import RoadMetric


def _problem(rng: np.random.Generator, m: int, n: int, ties: bool) -> tuple[np.ndarray, ...]:
    p, q = rng.random(m) + 1e-3, rng.random(n) + 1e-3
    if ties:
        p, q = np.ones(m), np.ones(n)  # equal masses: degenerate bases
    p, q = p / p.sum(), q / q.sum()
    cost = rng.random((m, n)) * 500.0
    if ties:
        cost = np.round(cost / 100.0) * 100.0
    return p, q, cost


@pytest.mark.parametrize("seed", range(40))
def test_solve_pair_is_the_lp(seed: int) -> None:
    """Random sizes (single rows and columns included), weights and costs, ties on odd seeds:
    the EMD of emd()'s network simplex and of its LP backend to 1e-9."""
    rng = np.random.default_rng([seed, 53])
    m = 1 if seed % 10 == 0 else int(rng.integers(1, 30))
    n = 1 if seed % 10 == 5 else int(rng.integers(1, 40))
    p, q, cost = _problem(rng, m, n, seed % 2 == 1)
    code, value = solve_pair(cost.ravel(), np.concatenate([p, -q]), m, n, 50)
    assert code == SOLVED
    for backend in ("network", "lp"):
        want = emd(p, q, cost, backend=backend).objective
        assert want is not None
        assert value == pytest.approx(want, rel=1e-9, abs=1e-9)


def _rows(rng: np.random.Generator, r: int, n: int, density: float) -> np.ndarray:
    w = rng.random((r, n)) * (rng.random((r, n)) < density)
    if rng.random() < 0.5:
        w = np.round(w * 4.0) / 4.0  # tied weights
    w[:, 0] += 1e-3
    for k in range(0, r, 3):  # single-node supports
        w[k] = 0.0
        w[k, int(rng.integers(n))] = 1.0
    return w / w.sum(axis=1, keepdims=True)


def _compare(metric: RoadMetric, p: np.ndarray, q: np.ndarray, gate: float,
             mass: float) -> tuple[int, int]:
    """solve_sources against the per-pair path on every pair the centroid bound keeps; returns
    (pairs proven by the kernel, pairs left to the per-pair path)."""
    sig_t, sig_q = truncate_rows(p, mass), truncate_rows(q, mass)
    pairs = np.argwhere(centroid_bound(metric, sig_t, sig_q) < gate * (1.0 + SLACK))
    solver = _TransportPairs(metric, sig_t, sig_q, pairs, gate)
    values, done = solve_sources(solver.blocks, pairs, gate * (1.0 + SLACK), Deadline(math.inf))
    single = _TransportPairs(metric, sig_t, sig_q, pairs, gate)
    dist = metric.network.shortest_paths(np.arange(metric.n_nodes))
    for n, (i, j) in enumerate(pairs):
        want, exact = single(int(i), int(j), sig_t[i], sig_q[j], gate, Deadline(math.inf))
        assert exact is True
        if not done[n]:
            continue
        if math.isinf(want):
            assert math.isinf(values[n])
            continue
        assert values[n] == pytest.approx(want, rel=1e-9, abs=1e-9)
        block = dist[np.ix_(sig_t[i].nodes, sig_q[j].nodes)]
        lp = emd(sig_t[i].weights, sig_q[j].weights, block, backend="lp").objective
        assert lp is not None and values[n] == pytest.approx(lp, rel=1e-9, abs=1e-9)
    return int(done.sum()), int((~done).sum())


@pytest.mark.parametrize("seed", range(30))
def test_batch_equals_the_per_pair_path_on_random_graphs(seed: int) -> None:
    """Random road graphs and supports (ties, single nodes), gated and not, Dijkstra or the
    junction table: every pair the kernel proves has the per-pair path's value (inf included)
    and the LP's to 1e-9."""
    rng = np.random.default_rng([seed, 59])
    net = random_network(int(rng.integers(4, 12)), float(rng.uniform(150.0, 600.0)), seed=seed)
    density = float(rng.uniform(0.02, 0.4))
    p = _rows(rng, int(rng.integers(1, 7)), net.n_nodes, density)
    q = _rows(rng, int(rng.integers(1, 7)), net.n_nodes, density)
    metric = RoadMetric(net, dense_junction_limit=3000 * (seed % 2))
    proven = 0
    for gate in (float(rng.uniform(50.0, 400.0)), math.inf):
        proven += _compare(metric, p, q, gate, float(rng.choice([0.9, 0.99, 1.0])))[0]
    assert proven > 0


def _two_lines() -> RoadNetwork:
    """Two straight roads of 6 nodes, 10 m apart, not joined: nodes 0–5 and 6–11."""
    x = np.concatenate([np.arange(6) * 10.0, np.arange(6) * 10.0])
    y = np.repeat([0.0, 500.0], 6)
    edges = np.array([[k, k + 1] for k in [*range(5), *range(6, 11)]])
    return RoadNetwork(np.column_stack([x, y]), edges, np.full(10, 10.0))


@pytest.mark.parametrize("table", [0, 3000])
def test_pairs_across_components_are_left_to_the_per_pair_path(table: int) -> None:
    """A support on both roads has inf entries in its block: the kernel leaves it (FALLBACK),
    the per-pair path settles it; pairs on one road are proven."""
    metric = RoadMetric(_two_lines(), dense_junction_limit=table)
    p = np.zeros((2, 12))
    p[0, [1, 8]] = [0.5, 0.5]
    p[1, 2] = 1.0
    q = np.zeros((1, 12))
    q[0, 4] = 1.0
    proven, left = _compare(metric, p, q, math.inf, 1.0)
    assert (proven, left) == (1, 1)


def test_capped_blocks_are_left_to_the_per_pair_path() -> None:
    """Dijkstra stopped at twice the gate caps the far end of a line: that pair falls back."""
    lengths = [10.0] * 20
    x = np.concatenate([[0.0], np.cumsum(lengths)])
    net = RoadNetwork(np.column_stack([x, np.zeros(21)]),
                      np.column_stack([np.arange(20), np.arange(1, 21)]), np.array(lengths))
    metric = RoadMetric(net, dense_junction_limit=0)
    p = np.zeros((2, 21))
    p[0, [0, 20]] = [0.9, 0.1]
    p[1, 3] = 1.0
    q = np.eye(21)[[2]]
    assert _compare(metric, p, q, 80.0, 1.0) == (1, 1)


def test_packed_offsets_and_normalised_weights() -> None:
    nodes, weights, ptr = packed([np.array([3, 5]), np.array([1])],
                                 [np.array([1.0, 3.0]), np.array([2.0])])
    assert nodes.tolist() == [3, 5, 1] and ptr.tolist() == [0, 2, 3]
    assert weights.tolist() == [0.25, 0.75, 1.0]
    assert FALLBACK != SOLVED
