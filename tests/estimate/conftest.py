"""Small road networks shared by the estimate tests."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models import RoadNetwork, grid_network
from searchtrack.models.road_particles import DirectedRoads


def path_network(n: int, spacing_m: float = 10.0) -> RoadNetwork:
    """A straight road of ``n`` nodes ``spacing_m`` apart along x."""
    coords = np.column_stack([np.arange(n) * spacing_m, np.zeros(n)])
    edges = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return RoadNetwork(coords, edges, np.full(n - 1, spacing_m), source=f"path {n}")


@pytest.fixture
def path3() -> RoadNetwork:
    """A three-node path."""
    return path_network(3)


@pytest.fixture
def path5() -> RoadNetwork:
    """A five-node path."""
    return path_network(5)


@pytest.fixture(scope="module")
def grid3() -> DirectedRoads:
    """The directed roads of paper 000's 3 × 3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def weighted_clouds(roads: DirectedRoads, seed: int) -> tuple[np.ndarray, np.ndarray,
                                                              np.ndarray]:
    """Six clouds of 400 particles uniform on ``roads`` with random normalized weights."""
    rng = np.random.default_rng(seed)
    edge, s = roads.uniform((6, 400), rng)
    w = rng.random((6, 400))
    return edge, s, w / w.sum(axis=1, keepdims=True)
