"""The receding-horizon planner of paper 004 (eqs. 7–8): the move it picks, ties, the in-box
sequences, statuses and the block-wise time limit."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.search import (
    ExplorationBonus,
    NoRefinement,
    SearchProblem,
    SearchSettings,
    solve,
)
from searchtrack.plan.search.receding import BLOCK, solve_receding

from .helpers import BOX, CENTRE, SENSOR, plan


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


def test_ties_go_to_the_first_sequence() -> None:
    """On a fresh bonus without refinement every sequence scores τ: the first, (+x, +x), wins,
    and the run is OPTIMAL with its score as bound."""
    problem = SearchProblem(CENTRE, BOX, ExplorationBonus(BOX, 20.0), SENSOR,
                            SearchSettings(horizon=2, refinement=NoRefinement()))
    result = solve_receding(problem)
    assert result.status is Status.OPTIMAL and result.plan is not None
    np.testing.assert_allclose(result.plan.sequence, [[72.0, 60.0, 60.0], [84.0, 60.0, 60.0]])
    assert result.objective == result.bound == pytest.approx(2.0)
    assert result.plan.exploration == pytest.approx(2.0) and result.plan.refinement == 0.0
    assert result.stats == {"sequences": 36.0, "scored": 36.0}


def test_sequences_are_limited_to_the_box() -> None:
    """From a corner of the box only the moves into it count: 3 of 6 for τ = 1."""
    problem = SearchProblem(np.zeros(3), BOX, ExplorationBonus(BOX, 20.0), SENSOR,
                            SearchSettings(refinement=NoRefinement()))
    result = solve_receding(problem)
    assert result.plan is not None and result.plan.candidates == 3


def test_expired_limit_scores_exactly_one_block() -> None:
    """τ = 4 gives 6⁴ = 1296 in-box sequences; a limit gone at the first look scores one block
    of BLOCK and answers FEASIBLE without bound."""
    problem = SearchProblem(CENTRE, BOX, ExplorationBonus(BOX, 20.0), SENSOR,
                            SearchSettings(horizon=4, refinement=NoRefinement()))
    result = solve_receding(problem, time_limit_s=1e-9)
    assert result.status is Status.FEASIBLE and result.bound is None
    assert result.stats == {"sequences": 1296.0, "scored": float(BLOCK)}
    full = solve_receding(problem)
    assert full.status is Status.OPTIMAL and full.stats["scored"] == 1296.0


def test_planar_lattice_keeps_the_altitude() -> None:
    """With dims=2 the 4² = 16 sequences of two planar moves stay at 60 m, so a target centre
    below and towards −y is approached along −y only."""
    centres = np.array([[60.0, 30.0, 20.0]])
    problem = SearchProblem(CENTRE, BOX, ExplorationBonus(BOX, 20.0), SENSOR,
                            SearchSettings(horizon=2, alpha=0.0, dims=2), centres=centres)
    result = solve_receding(problem)
    assert result.status is Status.OPTIMAL and result.plan is not None
    np.testing.assert_allclose(result.plan.sequence, [[60.0, 48.0, 60.0], [60.0, 36.0, 60.0]])
    assert result.stats == {"sequences": 16.0, "scored": 16.0}
