"""Receding-horizon search planner of paper 004 and the lawnmower baselines."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.assign.exploration import ExplorationBonus, empty_horizon_mi
from searchtrack.plan.assign.footprint import GaussianFieldOfView
from searchtrack.plan.search.lawnmower import lawnmower_2d, lawnmower_3d
from searchtrack.plan.search.receding import RecedingConfig, plan_search_step

BOX = np.array([[0.0, 120.0], [0.0, 120.0], [0.0, 120.0]])
SENSOR = GaussianFieldOfView(0.98, 25.0, 25.0)


def test_bonus_decreases_where_sensed_and_stays_in_unit_interval() -> None:
    """ι starts at 1, falls near the sensed pose, never leaves [0, 1]."""
    bonus = ExplorationBonus(BOX, 10.0)
    assert np.all(bonus.values == 1.0)
    bonus.update(SENSOR, np.array([60.0, 60.0, 60.0]))
    assert bonus.at(np.array([[60.0, 60.0, 60.0]]))[0] == pytest.approx(0.02, abs=1e-6)
    assert bonus.at(np.array([[0.0, 0.0, 0.0]]))[0] > 0.9
    assert np.all((bonus.values >= 0.0) & (bonus.values <= 1.0))


def test_refinement_picks_the_move_towards_the_target() -> None:
    """With a target centre straight ahead in +y, the planner moves +y (all horizons)."""
    bonus = ExplorationBonus(BOX, 10.0)
    centres = np.array([[60.0, 90.0, 60.0]])
    for tau in (1, 2, 3):
        step = plan_search_step(np.array([60.0, 60.0, 60.0]), BOX, bonus, SENSOR,
                                RecedingConfig(horizon=tau, alpha=0.0), centres=centres)
        np.testing.assert_allclose(step.waypoint, [60.0, 72.0, 60.0])
        assert step.candidates == 6**tau


def test_exploration_avoids_explored_region() -> None:
    """Exploration only: after sensing at −x side the planner moves towards +x."""
    bonus = ExplorationBonus(BOX, 10.0)
    bonus.update(SENSOR, np.array([40.0, 60.0, 60.0]))
    step = plan_search_step(np.array([60.0, 60.0, 60.0]), BOX, bonus, SENSOR,
                            RecedingConfig(refinement="none"))
    np.testing.assert_allclose(step.waypoint, [72.0, 60.0, 60.0])


def test_mi_refinement_prefers_the_particle_cloud() -> None:
    """MI refinement moves towards the particles."""
    bonus = ExplorationBonus(BOX, 20.0)
    rng = np.random.default_rng(0)
    pos = rng.normal([60.0, 60.0, 30.0], 2.0, size=(200, 3))
    w = np.full(200, 1.0 / 200)
    step = plan_search_step(np.array([60.0, 60.0, 60.0]), BOX, bonus, SENSOR,
                            RecedingConfig(alpha=0.0, refinement="mi"), positions=pos, weights=w)
    np.testing.assert_allclose(step.waypoint, [60.0, 60.0, 48.0])
    assert empty_horizon_mi(SENSOR, pos, w, step.sequence) > 0.0


def test_planner_bad_input() -> None:
    """Missing refinement inputs and bad configs raise naming the field."""
    bonus = ExplorationBonus(BOX, 10.0)
    with pytest.raises(InvalidInputError, match="centres"):
        plan_search_step(np.zeros(3), BOX, bonus, SENSOR, RecedingConfig())
    with pytest.raises(InvalidInputError, match="horizon"):
        RecedingConfig(horizon=0)
    with pytest.raises(InvalidInputError, match="resolution_m"):
        ExplorationBonus(BOX, 0.0)


def _max_gap(path: np.ndarray, pts: np.ndarray) -> float:
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
