"""The search problem, its settings and its plan: validation naming the field and the score
α E + T of paper 004 eq. (8)."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.search import (
    EmptyHorizonMI,
    ExplorationBonus,
    NoRefinement,
    SearchPlan,
    SearchProblem,
    SearchSettings,
    centre_probability,
    solve,
)

from .helpers import BOX, CENTRE, SENSOR


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


def test_scores_are_alpha_exploration_plus_refinement() -> None:
    """Eq. (8) on two sequences: E sums ι at the poses, T is the centre probability, the score
    is α E + T."""
    bonus = ExplorationBonus(BOX, 20.0).updated(SENSOR, CENTRE)
    centres = np.array([[60.0, 84.0, 60.0]])
    problem = SearchProblem(CENTRE, BOX, bonus, SENSOR, SearchSettings(horizon=2, alpha=0.5),
                            centres=centres)
    seqs = np.array([[[72.0, 60.0, 60.0], [84.0, 60.0, 60.0]],
                     [[60.0, 72.0, 60.0], [60.0, 84.0, 60.0]]])
    ex, ref, score = problem.scores(seqs)
    np.testing.assert_allclose(ex, [bonus.at(s).sum() for s in seqs], rtol=1e-12)
    np.testing.assert_allclose(ref, [centre_probability(SENSOR, centres, s) for s in seqs],
                               rtol=1e-12)
    np.testing.assert_allclose(score, 0.5 * ex + ref, rtol=1e-12)
    assert ref[1] > ref[0]


def test_waypoint_is_the_first_position() -> None:
    """The plan flies the first position of its sequence next."""
    seq = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    np.testing.assert_array_equal(SearchPlan(seq, 1.0, 0.5, 1.5, 36).waypoint, [1.0, 2.0, 3.0])


def test_inputs_are_read_only_copies() -> None:
    """The problem copies position, bounds and centres: the caller's arrays stay writable and
    later changes do not reach the problem."""
    position, centres = CENTRE.copy(), np.array([[1.0, 2.0, 3.0]])
    problem = SearchProblem(position, BOX, ExplorationBonus(BOX, 20.0), SENSOR,
                            centres=centres)
    position[0], centres[0, 0] = -1.0, -1.0
    assert problem.position[0] == 60.0 and problem.centres is not None
    assert problem.centres[0, 0] == 1.0
    assert not problem.position.flags.writeable and not problem.bounds.flags.writeable


def test_more_bad_fields() -> None:
    """Every remaining field out of its domain raises naming it."""
    bonus = ExplorationBonus(BOX, 10.0)
    none = SearchSettings(refinement=NoRefinement())
    for kwargs, field in (({"step_m": 0.0}, "step_m"), ({"alpha": -1.0}, "alpha"),
                          ({"dims": 1}, "dims"), ({"horizon": 6}, "horizon"),
                          ({"lawnmower_spacing_m": np.inf}, "lawnmower_spacing_m")):
        with pytest.raises(InvalidInputError, match=field):
            SearchSettings(**kwargs)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="position"):
        SearchProblem(np.array([0.0, np.nan, 0.0]), BOX, bonus, SENSOR, none)
    with pytest.raises(InvalidInputError, match="bounds"):
        SearchProblem(np.zeros(3), BOX[::-1, ::-1], bonus, SENSOR, none)
    with pytest.raises(InvalidInputError, match="bonus"):
        SearchProblem(np.zeros(3), BOX, "bonus", SENSOR, none)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="sensor"):
        SearchProblem(np.zeros(3), BOX, bonus, object(), none)  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="settings"):
        SearchProblem(np.zeros(3), BOX, bonus, SENSOR, {})  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="belief"):
        SearchProblem(np.zeros(3), BOX, bonus, SENSOR, SearchSettings(refinement=EmptyHorizonMI()),
                      belief=np.zeros((3, 3)))  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="centres"):
        SearchProblem(np.zeros(3), BOX, bonus, SENSOR, centres=np.zeros((2, 2)))
    ok = SearchProblem(np.zeros(3), BOX, bonus, SENSOR, SearchSettings(refinement=EmptyHorizonMI()),
                       belief=WeightedParticles(np.zeros((2, 3)), np.ones(2)))
    assert ok.belief is not None
