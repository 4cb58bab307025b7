"""Road maps shared by the fleet-bound tests: the paper's 3 × 3 grid and two irregular maps."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models import RoadNetwork, grid_network


def grid_3x3(block_m: float = 100.0, spacing_m: float | None = None) -> RoadNetwork:
    """The 3 × 3 map of paper 000 (Fig. 3, 6): nodes at the intersections unless ``spacing_m``."""
    return grid_network(3, 3, block_m, block_m if spacing_m is None else spacing_m)


def irregular() -> RoadNetwork:
    """A hand-made map with uneven roads, two dead ends, three pass-through nodes and junctions
    of degree 3 and 4 (road 4–1 is a diagonal; lengths are 5 % above the straight lines).

    ::

        3 ------- 4
        |       / |
        0 --- 1 - 2 - 5 (dead end)
              |
              6 ------- 7 (dead end)
    """
    coords = np.array([[0, 0], [70, 0], [130, 0], [0, 55], [130, 55], [160, 0], [70, -40],
                       [150, -40]], dtype=float)
    edges = np.array([[0, 1], [1, 2], [0, 3], [3, 4], [2, 4], [2, 5], [1, 6], [6, 7], [4, 1]])
    lengths = np.linalg.norm(coords[edges[:, 0]] - coords[edges[:, 1]], axis=1) * 1.05
    return RoadNetwork(coords, edges, lengths, source="irregular")


@pytest.fixture(scope="module")
def paper_grid() -> RoadNetwork:
    """3 × 3 intersections, 100 m blocks."""
    return grid_3x3()


@pytest.fixture(scope="module")
def odd_map() -> RoadNetwork:
    """The hand-made irregular map."""
    return irregular()
