"""The refinement terms T(q) of the search score (paper 004 eq. 8): what each needs from the
problem and its scores."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.search import (
    CentreProbability,
    EmptyHorizonMI,
    ExplorationBonus,
    NoRefinement,
    Refinement,
    SearchProblem,
    SearchSettings,
    centre_probability,
    empty_horizon_mi,
)

from .helpers import BOX, CENTRE, SENSOR, plan


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


SEQUENCES = np.array([[[72.0, 60.0, 60.0], [84.0, 60.0, 60.0]],
                      [[60.0, 48.0, 60.0], [60.0, 48.0, 48.0]]])


def _problem(refinement: Refinement, belief: WeightedParticles | None = None,
             centres: np.ndarray | None = None) -> SearchProblem:
    return SearchProblem(CENTRE, BOX, ExplorationBonus(BOX, 20.0), SENSOR,
                         SearchSettings(horizon=2, refinement=refinement), belief=belief,
                         centres=centres)


def test_terms_are_refinements_with_names() -> None:
    """The three terms satisfy the protocol and name themselves."""
    terms = (CentreProbability(), EmptyHorizonMI(), NoRefinement())
    assert all(isinstance(t, Refinement) for t in terms)
    assert [t.name for t in terms] == ["centre", "mi", "none"]
    assert not isinstance("centre", Refinement)


def test_centre_probability_scores_each_sequence() -> None:
    """Eq. (11) per sequence; no centre scores 0; a problem without centres is refused."""
    centres = np.array([[84.0, 60.0, 60.0], [60.0, 40.0, 50.0]])
    problem = _problem(CentreProbability(), centres=centres)
    np.testing.assert_allclose(CentreProbability().scores(problem, SEQUENCES),
                               [centre_probability(SENSOR, centres, s) for s in SEQUENCES])
    empty = _problem(CentreProbability(), centres=np.zeros((0, 3)))
    np.testing.assert_array_equal(CentreProbability().scores(empty, SEQUENCES), [0.0, 0.0])
    with pytest.raises(InvalidInputError, match="centres"):
        _problem(CentreProbability())


def test_empty_horizon_mi_scores_each_sequence() -> None:
    """The empty-horizon MI per sequence on the belief's particles; no belief is refused."""
    rng = np.random.default_rng(2)
    belief = WeightedParticles(rng.normal(CENTRE, 8.0, size=(50, 3)), np.full(50, 0.04))
    problem = _problem(EmptyHorizonMI(), belief=belief)
    expected = [empty_horizon_mi(SENSOR, belief.positions, belief.weights, s)
                for s in SEQUENCES]
    np.testing.assert_allclose(EmptyHorizonMI().scores(problem, SEQUENCES), expected)
    assert min(expected) > 0.0
    with pytest.raises(InvalidInputError, match="belief"):
        _problem(EmptyHorizonMI())


def test_no_refinement_needs_nothing_and_scores_zero() -> None:
    """Exploration only: no centres or belief needed, every sequence scores 0."""
    problem = _problem(NoRefinement())
    np.testing.assert_array_equal(NoRefinement().scores(problem, SEQUENCES), [0.0, 0.0])
