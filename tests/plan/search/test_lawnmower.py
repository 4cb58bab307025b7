"""Lawnmower coverage baselines (papers 003, 004): 2-D and 3-D patterns, their coverage and
the search backend that follows them."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.core.types import FloatArray
from searchtrack.plan.search import (
    ExplorationBonus,
    NoRefinement,
    SearchProblem,
    SearchSettings,
    lawnmower_2d,
    lawnmower_3d,
    solve,
)
from searchtrack.plan.search.lawnmower import lawnmower_supports, solve_lawnmower

from .helpers import BOX, SENSOR


def test_lawnmower_backend_follows_the_pattern() -> None:
    """From a waypoint of the 3-D lawnmower the backend returns the next τ waypoints."""
    route = lawnmower_3d(BOX, 48.0, 48.0, 12.0)
    bonus = ExplorationBonus(BOX, 20.0)
    settings = SearchSettings(horizon=2, refinement=NoRefinement())
    result = solve(SearchProblem(route[5], BOX, bonus, SENSOR, settings), backend="lawnmower")
    assert result.status is Status.FEASIBLE and result.plan is not None
    np.testing.assert_array_equal(result.plan.sequence, route[6:8])
    end = solve(SearchProblem(route[-1], BOX, bonus, SENSOR, settings), backend="lawnmower")
    assert end.plan is not None
    np.testing.assert_array_equal(end.plan.sequence, route[[-1, -1]])

def _max_gap(path: FloatArray, pts: FloatArray) -> float:
    d = np.linalg.norm(pts[:, None, :] - path[None, :, :], axis=2)
    return float(d.min(axis=1).max())

def test_lawnmower_2d_covers_the_area() -> None:
    """Every point of the area lies within spacing/2 (plus half a step) of the 2-D path."""
    path = lawnmower_2d(np.array([[0.0, 100.0], [0.0, 60.0]]), 20.0, 15.0, 5.0)
    assert np.all(path[:, 2] == 15.0)
    assert np.all(np.linalg.norm(np.diff(path[:, :2], axis=0), axis=1) <= 5.0 + 1e-9)
    g = np.stack(np.meshgrid(np.linspace(0, 100, 41), np.linspace(0, 60, 25)), -1).reshape(-1, 2)
    assert _max_gap(path[:, :2], g) <= np.hypot(10.0, 2.5) + 1e-9

def test_lawnmower_3d_covers_the_volume() -> None:
    """Layers every layer_spacing cover the box within half the spacings; steps ≤ step_m."""
    path = lawnmower_3d(BOX, 48.0, 48.0, 12.0)
    assert np.all(np.linalg.norm(np.diff(path, axis=0), axis=1) <= 12.0 + 1e-9)
    axis = np.linspace(0, 120, 13)
    g = np.stack(np.meshgrid(axis, axis, axis), -1).reshape(-1, 3)
    assert _max_gap(path, g) <= np.sqrt(2 * 20.0**2 + 6.0**2) + 1e-9
    with pytest.raises(InvalidInputError, match="bounds"):
        lawnmower_3d(BOX[:2], 48.0, 48.0, 12.0)


AREA = np.array([[0.0, 100.0], [0.0, 40.0]])


def test_lawnmower_2d_by_hand() -> None:
    """A 100 × 40 m area at 20 m spacing: lines at y = 10 and 30, the second flown back,
    sampled every 50 m."""
    path = lawnmower_2d(AREA, 20.0, 7.0, 50.0)
    np.testing.assert_allclose(path, [[0, 10, 7], [50, 10, 7], [100, 10, 7], [100, 30, 7],
                                      [50, 30, 7], [0, 30, 7]])


def test_lawnmower_3d_by_hand() -> None:
    """Two layers at z = 10 and 30; the upper one is flown in reverse from the corner where the
    lower ends, joined by one 20 m climb."""
    path = lawnmower_3d(np.vstack([AREA, [[0.0, 40.0]]]), 20.0, 20.0, 50.0)
    lower = lawnmower_2d(AREA, 20.0, 10.0, 50.0)
    upper = lawnmower_2d(AREA, 20.0, 30.0, 50.0)[::-1]
    np.testing.assert_allclose(path, np.concatenate([lower, upper]))
    assert np.linalg.norm(path[6] - path[5]) == pytest.approx(20.0)


def test_lawnmower_bad_input() -> None:
    """Bad boxes, spacings, altitudes and steps raise naming the field."""
    with pytest.raises(InvalidInputError, match="bounds"):
        lawnmower_2d(np.array([[0.0, 10.0], [5.0, 5.0]]), 1.0, 1.0, 1.0)
    with pytest.raises(InvalidInputError, match="spacing_m"):
        lawnmower_2d(AREA, 0.0, 1.0, 1.0)
    with pytest.raises(InvalidInputError, match="step_m"):
        lawnmower_2d(AREA, 1.0, 1.0, -1.0)
    with pytest.raises(InvalidInputError, match="altitude_m"):
        lawnmower_2d(AREA, 1.0, np.nan, 1.0)
    with pytest.raises(InvalidInputError, match="layer_spacing_m"):
        lawnmower_3d(BOX, 48.0, 0.0, 12.0)


def test_planar_backend_flies_at_the_uav_altitude() -> None:
    """With 2-D settings the backend follows the 2-D pattern at the UAV's altitude, from the
    waypoint after the nearest one, and reports the sequence's score as its objective."""
    bonus = ExplorationBonus(BOX, 20.0)
    settings = SearchSettings(horizon=3, dims=2, refinement=NoRefinement(),
                              lawnmower_spacing_m=48.0)
    problem = SearchProblem(np.array([1.0, 20.0, 33.0]), BOX, bonus, SENSOR, settings)
    result = solve_lawnmower(problem)
    route = lawnmower_2d(BOX[:2], 48.0, 33.0, 12.0)
    assert result.status is Status.FEASIBLE and result.plan is not None
    np.testing.assert_array_equal(result.plan.sequence, route[1:4])
    assert result.objective == pytest.approx(3.0)  # fresh bonus, α = 1, no refinement
    assert result.bound is None


def test_lawnmower_supports() -> None:
    """A box flat along a swept axis is refused; z may be flat for a 2-D pattern."""
    flat = np.array([[0.0, 120.0], [0.0, 120.0], [50.0, 50.0]])
    bonus = ExplorationBonus(BOX, 20.0)
    three = SearchProblem(np.array([0.0, 0.0, 50.0]), flat, bonus, SENSOR,
                          SearchSettings(refinement=NoRefinement()))
    two = SearchProblem(np.array([0.0, 0.0, 50.0]), flat, bonus, SENSOR,
                        SearchSettings(refinement=NoRefinement(), dims=2))
    assert "lo < hi" in (lawnmower_supports(three) or "")
    assert lawnmower_supports(two) is None
