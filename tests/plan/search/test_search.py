"""The search family of paper 004: exploration bonus, lattice, receding planner, lawnmowers."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.core.types import FloatArray
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.search import (
    EmptyHorizonMI,
    ExplorationBonus,
    NoRefinement,
    SearchPlan,
    SearchProblem,
    SearchSettings,
    empty_horizon_mi,
    lattice_moves,
    lattice_sequences,
    lawnmower_2d,
    lawnmower_3d,
    solve,
)

BOX = np.array([[0.0, 120.0], [0.0, 120.0], [0.0, 120.0]])
SENSOR = GaussianFieldOfView(0.98, 25.0, 25.0)
CENTRE = np.array([60.0, 60.0, 60.0])


def plan(problem: SearchProblem, backend: str = "receding") -> SearchPlan:
    """The plan of a solve that must succeed."""
    result = solve(problem, backend=backend)
    assert result.plan is not None, result.message
    return result.plan


def test_bonus_decreases_where_sensed_and_stays_in_unit_interval() -> None:
    """ι starts at 1, falls near the sensed pose, never leaves [0, 1]."""
    fresh = ExplorationBonus(BOX, 10.0)
    assert np.all(fresh.values == 1.0)
    bonus = fresh.updated(SENSOR, CENTRE)
    assert np.all(fresh.values == 1.0)  # immutable: updated returns a new bonus
    assert bonus.at(np.array([[60.0, 60.0, 60.0]]))[0] == pytest.approx(0.02, abs=1e-6)
    assert bonus.at(np.array([[0.0, 0.0, 0.0]]))[0] > 0.9
    assert np.all((bonus.values >= 0.0) & (bonus.values <= 1.0))


def test_refinement_picks_the_move_towards_the_target() -> None:
    """With a target centre straight ahead in +y, the planner moves +y (all horizons)."""
    bonus = ExplorationBonus(BOX, 10.0)
    centres = np.array([[60.0, 90.0, 60.0]])
    for tau in (1, 2, 3):
        result = solve(SearchProblem(CENTRE, BOX, bonus, SENSOR,
                                     SearchSettings(horizon=tau, alpha=0.0), centres=centres))
        assert result.status is Status.OPTIMAL and result.plan is not None
        np.testing.assert_allclose(result.plan.waypoint, [60.0, 72.0, 60.0])
        assert result.plan.candidates == 6**tau
        assert result.objective == pytest.approx(result.plan.score)


def test_exploration_avoids_explored_region() -> None:
    """Exploration only: after sensing at −x side the planner moves towards +x."""
    bonus = ExplorationBonus(BOX, 10.0).updated(SENSOR, np.array([40.0, 60.0, 60.0]))
    step = plan(SearchProblem(CENTRE, BOX, bonus, SENSOR, SearchSettings(
        refinement=NoRefinement())))
    np.testing.assert_allclose(step.waypoint, [72.0, 60.0, 60.0])


def test_mi_refinement_prefers_the_particle_cloud() -> None:
    """MI refinement moves towards the particles."""
    bonus = ExplorationBonus(BOX, 20.0)
    rng = np.random.default_rng(0)
    pos = rng.normal([60.0, 60.0, 30.0], 2.0, size=(200, 3))
    w = np.full(200, 1.0 / 200)
    step = plan(SearchProblem(CENTRE, BOX, bonus, SENSOR, SearchSettings(
        alpha=0.0, refinement=EmptyHorizonMI()), belief=WeightedParticles(pos, w)))
    np.testing.assert_allclose(step.waypoint, [60.0, 60.0, 48.0])
    assert empty_horizon_mi(SENSOR, pos, w, step.sequence) > 0.0


def test_planner_bad_input() -> None:
    """Missing refinement inputs and bad settings raise naming the field."""
    bonus = ExplorationBonus(BOX, 10.0)
    with pytest.raises(InvalidInputError, match="centres"):
        SearchProblem(np.zeros(3), BOX, bonus, SENSOR, SearchSettings())
    with pytest.raises(InvalidInputError, match="belief"):
        SearchProblem(np.zeros(3), BOX, bonus, SENSOR, SearchSettings(refinement=EmptyHorizonMI()))
    with pytest.raises(InvalidInputError, match="refinement"):
        SearchSettings(refinement="centre")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="horizon"):
        SearchSettings(horizon=0)
    with pytest.raises(InvalidInputError, match="resolution_m"):
        ExplorationBonus(BOX, 0.0)
    with pytest.raises(InvalidInputError, match="position"):
        SearchProblem(np.zeros(2), BOX, bonus, SENSOR, SearchSettings(), centres=np.zeros((0, 3)))
    with pytest.raises(InvalidInputError, match="backend"):
        solve(SearchProblem(np.zeros(3), BOX, bonus, SENSOR, centres=np.zeros((0, 3))),
              backend="nope")


def test_no_sequence_in_the_box_is_infeasible() -> None:
    """A box smaller than one move leaves no sequence: INFEASIBLE, no plan."""
    box = np.array([[0.0, 5.0]] * 3)
    result = solve(SearchProblem(np.zeros(3), box, ExplorationBonus(box, 1.0), SENSOR,
                                 SearchSettings(refinement=NoRefinement())))
    assert result.status is Status.INFEASIBLE and result.plan is None


def test_tiny_time_limit_still_answers() -> None:
    """A limit that expires at once still scores the first block (FEASIBLE when τ = 4 has
    more sequences than one block, OPTIMAL otherwise), with a valid plan."""
    bonus = ExplorationBonus(BOX, 20.0)
    problem = SearchProblem(CENTRE, BOX, bonus, SENSOR,
                            SearchSettings(horizon=4, refinement=NoRefinement()))
    result = solve(problem, time_limit_s=1e-9)
    assert result.status in (Status.FEASIBLE, Status.OPTIMAL) and result.plan is not None


def test_lattice_moves_and_sequences() -> None:
    """Six axis moves; sequences leaving the box are dropped; count is 6^τ inside."""
    moves = lattice_moves(12.0)
    assert moves.shape == (6, 3)
    assert np.allclose(np.linalg.norm(moves, axis=1), 12.0)
    box = np.array([[-100.0, 100.0]] * 3)
    assert lattice_sequences(np.zeros(3), moves, 2, box).shape == (36, 2, 3)
    corner = np.array([[0.0, 100.0]] * 3)
    seqs = lattice_sequences(np.zeros(3), moves, 1, corner)
    assert seqs.shape == (3, 1, 3)
    with pytest.raises(InvalidInputError, match="step_m"):
        lattice_moves(-1.0)


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
