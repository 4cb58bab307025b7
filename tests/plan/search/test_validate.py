"""The search family's validator: every planner's step passes it; steps with a wrong score, a
leap off the lattice or a position outside the box come back as ERROR."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.search import (
    BACKENDS,
    ExplorationBonus,
    SearchProblem,
    SearchSettings,
    solve,
)
from searchtrack.plan.search.validate import answer_problems, interpolated

from .helpers import BOX, CENTRE, SENSOR


def _problem(seed: int) -> SearchProblem:
    rng = np.random.default_rng(seed)
    bonus = ExplorationBonus(BOX, float(rng.choice([7.5, 10.0, 12.5])))
    for _ in range(3):
        bonus = bonus.updated(SENSOR, rng.uniform(BOX[:, 0], BOX[:, 1]))
    centres = rng.uniform(BOX[:, 0], BOX[:, 1], size=(2, 3))
    return SearchProblem(CENTRE, BOX, bonus, SENSOR,
                         SearchSettings(horizon=int(rng.integers(1, 3)), alpha=1.5),
                         centres=centres)


@pytest.mark.parametrize("seed", range(5))
def test_every_backend_passes(seed: int) -> None:
    """Receding and lawnmower answers hold under the validator."""
    problem = _problem(seed)
    for name in BACKENDS.names():
        result = solve(problem, backend=name)
        assert result.status is not Status.ERROR, result.message
        assert answer_problems(problem, result) == []


def test_wrong_answers_are_rejected() -> None:
    """A score off by 1e-6, a two-step leap and a position outside the box are each named."""
    problem = _problem(0)
    good = solve(problem)
    assert good.plan is not None and good.objective is not None
    lie = dataclasses.replace(good, objective=good.objective + 1e-6)
    assert "objective" in " ".join(answer_problems(problem, lie))
    seq = good.plan.sequence.copy()
    seq[0] = problem.position + np.array([24.0, 0.0, 0.0])
    leap = dataclasses.replace(good, plan=dataclasses.replace(good.plan, sequence=seq))
    assert any("lattice move" in p for p in answer_problems(problem, leap))
    seq = good.plan.sequence.copy()
    seq[-1] = BOX[:, 1] + 1.0
    out = dataclasses.replace(good, plan=dataclasses.replace(good.plan, sequence=seq))
    assert answer_problems(problem, out) == ["the sequence leaves the search box"]
    assert BACKENDS.validated(problem, lie).status is Status.ERROR


def test_interpolation_matches_the_bonus() -> None:
    """The validator's own multilinear interpolation agrees with the bonus's at random points."""
    problem = _problem(3)
    pts = np.random.default_rng(4).uniform(BOX[:, 0], BOX[:, 1], size=(50, 3))
    np.testing.assert_allclose(interpolated(problem.bonus.axes, problem.bonus.values, pts),
                               problem.bonus.at(pts), atol=1e-12)
