"""Small road networks shared by the estimate tests."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models import RoadNetwork


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
