"""The Gaussian road kernel: against its formula on road distances found by brute force."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.road_kernel import TRUNCATION_SIGMAS, RoadKernel
from searchtrack.models import RoadNetwork
from tests.estimate.conftest import path_network


def floyd_warshall(n: int, edges: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """All road distances by relaxing every triple (independent of Dijkstra)."""
    d = np.full((n, n), math.inf)
    np.fill_diagonal(d, 0.0)
    for (a, b), ell in zip(edges.tolist(), lengths.tolist(), strict=True):
        d[a, b] = d[b, a] = min(d[a, b], ell)
    for k, i, j in itertools.product(range(n), repeat=3):
        if d[i, k] + d[k, j] < d[i, j]:
            d[i, j] = d[i, k] + d[k, j]
    return d


def expected_kernel(d: np.ndarray, sigma: float) -> np.ndarray:
    """The kernel's formula: Gaussian weights of road distance, cut at 3σ, rows normalised."""
    w = np.where(d <= TRUNCATION_SIGMAS * sigma, np.exp(-0.5 * (d / sigma) ** 2), 0.0)
    return w / w.sum(axis=1, keepdims=True)


def random_network(rng: np.random.Generator, n: int) -> RoadNetwork:
    """A random connected-or-not road network: a random tree plus chords, random lengths;
    coordinates unrelated to the lengths (the kernel must use road distance only)."""
    edges = {(int(rng.integers(0, k)), k) for k in range(1, n) if rng.random() < 0.85}
    for _ in range(n // 3):
        a, b = sorted(rng.choice(n, size=2, replace=False).tolist())
        edges.add((a, b))
    e = np.array(sorted(edges or {(0, 1)}), dtype=np.int64)
    return RoadNetwork(rng.uniform(0, 50, (n, 2)), e, rng.uniform(1.0, 15.0, len(e)))


@pytest.mark.parametrize("seed", range(12))
def test_kernel_equals_its_formula_on_random_networks(seed: int) -> None:
    rng = np.random.default_rng(seed)
    net = random_network(rng, int(rng.integers(3, 14)))
    sigma = float(rng.uniform(2.0, 12.0))
    kernel = RoadKernel(net, sigma)
    want = expected_kernel(floyd_warshall(net.n_nodes, net.edges, net.lengths_m), sigma)
    np.testing.assert_allclose(kernel.matrix.toarray(), want, rtol=1e-12, atol=1e-15)
    p = rng.dirichlet(np.ones(net.n_nodes))
    np.testing.assert_allclose(kernel.smooth(p), p @ want, rtol=1e-12, atol=1e-15)
    assert kernel.smooth(p).sum() == pytest.approx(1.0, abs=1e-12)


def test_mass_stays_on_its_own_road() -> None:
    """Two parallel roads 2 m apart, not joined: none of one's mass reaches the other."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 2.0], [10.0, 2.0]])
    net = RoadNetwork(coords, np.array([[0, 1], [2, 3]]), np.array([10.0, 10.0]))
    out = RoadKernel(net, 10.0).smooth([1.0, 0.0, 0.0, 0.0])
    assert out[2] == 0.0 and out[3] == 0.0
    assert out[0] > out[1] > 0.0


def test_a_point_mass_spreads_as_a_gaussian_along_a_road() -> None:
    """On a long straight road the kernel's row at a central node is the sampled Gaussian."""
    net = path_network(41, spacing_m=1.0)
    out = RoadKernel(net, 4.0).smooth(np.eye(41)[20])
    x = np.arange(41) - 20.0
    g = np.where(np.abs(x) <= 12.0, np.exp(-0.5 * (x / 4.0) ** 2), 0.0)
    np.testing.assert_allclose(out, g / g.sum(), rtol=1e-12)
    assert out[20] == pytest.approx(1.0 / (4.0 * math.sqrt(2.0 * math.pi)), rel=0.01)


@pytest.mark.parametrize("sigma", [0.0, -1.0, math.inf, math.nan, "10", True])
def test_bad_sigma_is_named(sigma: object) -> None:
    with pytest.raises(InvalidInputError, match="sigma_m"):
        RoadKernel(path_network(3), sigma)  # type: ignore[arg-type]


def test_bad_vector_is_named() -> None:
    kernel = RoadKernel(path_network(4), 5.0)
    with pytest.raises(InvalidInputError, match="probability"):
        kernel.smooth([0.5, 0.5])
    with pytest.raises(InvalidInputError, match="probability"):
        kernel.smooth([0.5, 0.5, math.nan, 0.0])
