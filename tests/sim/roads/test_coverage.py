"""Road coverage memory: footprints stamp the nodes they cover; coverage fades with age."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models import grid_network
from searchtrack.sim.roads.coverage import CoverageMemory


def test_footprints_stamp_nodes_and_coverage_fades() -> None:
    """Nodes within the radius of a UAV get coverage 1 now and ``e^{-1}`` one memory later;
    nodes never covered stay at 0."""
    net = grid_network(3, 3, 100.0, 50.0)  # 200 m square, nodes 50 m apart
    memory = CoverageMemory(net, radius_m=60.0, memory_s=10.0)
    np.testing.assert_array_equal(memory.level(0.0), np.zeros(net.n_nodes))
    memory.see(np.array([[0.0, 0.0]]), 5.0)
    near = np.hypot(*net.coords.T) <= 60.0
    assert near.sum() == 3  # the corner and its two neighbours
    np.testing.assert_allclose(memory.level(5.0), near.astype(float))
    np.testing.assert_allclose(memory.level(15.0), near * math.exp(-1.0))
    memory.see(np.array([[200.0, 200.0], [0.0, 0.0]]), 15.0)
    assert np.count_nonzero(memory.level(15.0) == 1.0) == 6


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"radius_m": 0.0, "memory_s": 1.0}, "radius_m"),
    ({"radius_m": 10.0, "memory_s": -1.0}, "memory_s"),
    ({"radius_m": 10.0, "memory_s": math.inf}, "memory_s"),
])
def test_bad_settings_are_named(kwargs: dict[str, float], field: str) -> None:
    """Radius and memory must be positive and finite."""
    with pytest.raises(InvalidInputError) as info:
        CoverageMemory(grid_network(2, 2, 100.0, 50.0), **kwargs)
    assert info.value.field == field
