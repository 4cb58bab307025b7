"""Entropy per target of a particle PHD (paper 003, eq. 15)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import PHDState, entropy_per_target

from .helpers import AREA


def test_entropy_per_target_of_uniform_phd() -> None:
    """Uniform particles on the grid give H[p] − log λ = log(area) − log λ (eq. 15)."""
    g = (np.arange(10) + 0.5) * 100.0
    xy = np.array([[a, b] for a in g for b in g])
    st = PHDState.from_particles(xy, np.full(100, 0.05))
    h = entropy_per_target(st, AREA, 100.0)
    assert h == pytest.approx(math.log(1e6) - math.log(5.0))
    one = PHDState.from_particles(np.array([[50.0, 50.0]]), np.array([1.0]))
    assert entropy_per_target(one, AREA, 100.0) == pytest.approx(math.log(1e4))
    assert math.isnan(entropy_per_target(PHDState.empty(2), AREA, 100.0))


def test_two_equal_cells_by_hand() -> None:
    """Mass split equally over two 100 m cells, λ = 1: H[p] = log 2 + log(10⁴) (eq. 15)."""
    st = PHDState.from_particles(np.array([[50.0, 50.0], [950.0, 950.0]]), np.array([0.5, 0.5]))
    assert entropy_per_target(st, AREA, 100.0) == pytest.approx(math.log(2.0) + math.log(1e4))


def test_particles_outside_count_in_the_edge_cell() -> None:
    """A particle outside the bounds counts in the nearest edge cell: one cell, λ = 2 gives
    log(cell area) − log 2, the same as a particle inside that cell."""
    outside = PHDState.from_particles(np.array([[-50.0, -50.0]]), np.array([2.0]))
    inside = PHDState.from_particles(np.array([[10.0, 10.0]]), np.array([2.0]))
    expected = math.log(1e4) - math.log(2.0)
    assert entropy_per_target(outside, AREA, 100.0) == pytest.approx(expected)
    assert entropy_per_target(inside, AREA, 100.0) == pytest.approx(expected)


def test_three_dimensional_cells_are_volumes() -> None:
    """In 3-D the cell size is cell_m³: one particle of unit mass gives log(10³)."""
    st = PHDState.from_particles(np.array([[1.0, 1.0, 1.0]]), np.array([1.0]), position_dim=3)
    bounds = [[0.0, 100.0]] * 3
    assert entropy_per_target(st, bounds, 10.0) == pytest.approx(math.log(1e3))


def test_bad_bounds_and_cells_name_the_field() -> None:
    """A non-positive cell, bounds of the wrong dimension or with low ≥ high are refused."""
    st = PHDState.from_particles(np.array([[1.0, 1.0]]), np.array([1.0]))
    with pytest.raises(InvalidInputError, match="cell_m"):
        entropy_per_target(st, AREA, 0.0)
    with pytest.raises(InvalidInputError, match="bounds"):
        entropy_per_target(st, [[0.0, 1.0]] * 3, 1.0)
    with pytest.raises(InvalidInputError, match="bounds"):
        entropy_per_target(st, [[0.0, 1.0], [5.0, 5.0]], 1.0)
