"""Every search backend on a catalogue of small problems whose optimum enumeration knows."""

from __future__ import annotations

import itertools
from collections.abc import Callable

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.search import (
    BACKENDS,
    CentreProbability,
    EmptyHorizonMI,
    ExplorationBonus,
    NoRefinement,
    SearchProblem,
    SearchSettings,
    solve,
)
from searchtrack.plan.search.exploration import (
    centre_probability,
    empty_horizon_mi,
    exploration_value,
)

BOX = np.array([[0.0, 96.0]] * 3)
SENSOR = GaussianFieldOfView(0.98, 25.0, 25.0)
MOVES = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]]) * 12.0


def centre_ahead() -> SearchProblem:
    """Refinement only, one centre 36 m ahead in +y: every optimal sequence heads for it."""
    return SearchProblem(np.array([48.0, 48.0, 48.0]), BOX, ExplorationBonus(BOX, 12.0), SENSOR,
                         SearchSettings(horizon=2, alpha=0.0),
                         centres=np.array([[48.0, 84.0, 48.0]]))


def explored_corner() -> SearchProblem:
    """Exploration only after sensing twice near the start: the plan leaves the sensed region."""
    bonus = ExplorationBonus(BOX, 12.0)
    for pose in ([24.0, 24.0, 24.0], [36.0, 24.0, 24.0]):
        bonus = bonus.updated(SENSOR, np.array(pose))
    return SearchProblem(np.array([24.0, 24.0, 24.0]), BOX, bonus, SENSOR,
                         SearchSettings(horizon=3, refinement=NoRefinement()))


def particle_cloud() -> SearchProblem:
    """Exploration plus empty-horizon MI on a particle cloud below the UAV, at the box edge."""
    rng = np.random.default_rng(3)
    pos = rng.normal([60.0, 30.0, 10.0], 3.0, size=(60, 3))
    belief = WeightedParticles(pos, np.full(60, 2.0 / 60))
    return SearchProblem(np.array([60.0, 36.0, 0.0]), BOX, ExplorationBonus(BOX, 24.0), SENSOR,
                         SearchSettings(horizon=2, alpha=0.5, refinement=EmptyHorizonMI()),
                         belief=belief)


def combined() -> SearchProblem:
    """Exploration plus centre refinement with two centres, τ = 1 at a corner."""
    bonus = ExplorationBonus(BOX, 12.0).updated(SENSOR, np.array([12.0, 0.0, 0.0]))
    return SearchProblem(np.zeros(3), BOX, bonus, SENSOR, SearchSettings(horizon=1),
                         centres=np.array([[0.0, 30.0, 0.0], [40.0, 0.0, 10.0]]))


CATALOGUE: dict[str, Callable[[], SearchProblem]] = {
    "centre_ahead": centre_ahead, "explored_corner": explored_corner,
    "particle_cloud": particle_cloud, "combined": combined,
}


def score(problem: SearchProblem, sequence: np.ndarray) -> float:
    """``α E + T`` of one sequence, term by term (eqs. 8, 10, 11)."""
    s = problem.settings
    value = s.alpha * exploration_value(problem.bonus, sequence)
    if isinstance(s.refinement, CentreProbability):
        assert problem.centres is not None
        value += centre_probability(problem.sensor, problem.centres, sequence)
    elif isinstance(s.refinement, EmptyHorizonMI):
        assert problem.belief is not None
        value += empty_horizon_mi(problem.sensor, problem.belief.positions,
                                  problem.belief.weights, sequence)
    return value


def optimum(problem: SearchProblem) -> tuple[float, np.ndarray]:
    """Best score and sequence by plain enumeration of the in-box lattice sequences."""
    best: tuple[float, np.ndarray] | None = None
    for combo in itertools.product(range(6), repeat=problem.settings.horizon):
        seq = problem.position + np.cumsum(MOVES[list(combo)], axis=0)
        if np.all((seq >= BOX[:, 0]) & (seq <= BOX[:, 1])):
            value = score(problem, seq)
            if best is None or value > best[0]:
                best = (value, seq)
    assert best is not None
    return best


def test_known_optimum_of_centre_ahead() -> None:
    """Heading straight for the centre is optimal (two +y moves)."""
    _value, seq = optimum(centre_ahead())
    np.testing.assert_allclose(seq, [[48.0, 60.0, 48.0], [48.0, 72.0, 48.0]])


@pytest.mark.parametrize("name", sorted(CATALOGUE))
@pytest.mark.parametrize("backend", BACKENDS.names())
def test_backend_on_catalogue(backend: str, name: str) -> None:
    """The exact backend finds the enumerated optimum (score and sequence, ties to the first);
    the others return an in-box sequence of the horizon whose score is what they report; a
    backend that cannot take the problem is refused naming ``backend``."""
    problem = CATALOGUE[name]()
    chosen = BACKENDS.get(backend)
    reason = chosen.supports(problem)
    if reason is not None:
        with pytest.raises(InvalidInputError, match="backend") as refused:
            solve(problem, backend=backend)
        assert refused.value.field == "backend" and refused.value.reason == reason
        return
    result = solve(problem, backend=backend)
    assert result.status.has_plan and result.plan is not None and result.objective is not None
    plan = result.plan
    assert plan.sequence.shape == (problem.settings.horizon, 3)
    assert np.all((plan.sequence >= BOX[:, 0]) & (plan.sequence <= BOX[:, 1]))
    assert result.objective == pytest.approx(score(problem, plan.sequence), rel=1e-9, abs=1e-12)
    if chosen.exact:
        value, seq = optimum(problem)
        assert result.status is Status.OPTIMAL
        assert result.objective == pytest.approx(value, rel=1e-9, abs=1e-12)
        np.testing.assert_allclose(plan.sequence, seq)
