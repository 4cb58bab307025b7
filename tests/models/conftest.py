"""Fixtures shared by the models tests."""

from __future__ import annotations

import pytest

from searchtrack.models import RoadNetwork, grid_network


@pytest.fixture(scope="module")
def grid() -> RoadNetwork:
    """A 3 × 3 grid of 100 m blocks (a 200 m square) with nodes every 10 m."""
    return grid_network(3, 3, 100.0, 10.0)
