"""solve() for a search step: the registry, the default backend and the checks every solve
makes."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.search import (
    BACKENDS,
    ExplorationBonus,
    NoRefinement,
    SearchProblem,
    SearchSettings,
    solve,
)

from .helpers import BOX, CENTRE, SENSOR


def _problem(bounds: np.ndarray = BOX) -> SearchProblem:
    return SearchProblem(CENTRE, bounds, ExplorationBonus(BOX, 20.0), SENSOR,
                         SearchSettings(refinement=NoRefinement()))


def test_registry_lists_the_backends() -> None:
    """``auto`` (the receding planner), the exact receding planner and the lawnmower pattern,
    in that order."""
    assert BACKENDS.names() == ["auto", "receding", "lawnmower"]
    assert [BACKENDS.get(n).exact for n in BACKENDS.names()] == [True, True, False]


def test_default_backend_is_the_receding_planner() -> None:
    """Without a backend name the receding planner answers, with no time limit."""
    result = solve(_problem())
    assert result.backend == "receding" and result.plan is not None
    assert result.stats["scored"] == result.stats["sequences"]


def test_solve_checks_limit_seed_and_support() -> None:
    """A bad limit or seed raises naming it; a box flat along z is refused by the lawnmower,
    naming ``backend``."""
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(_problem(), time_limit_s=-1.0)
    with pytest.raises(InvalidInputError, match="seed"):
        solve(_problem(), seed=2**31)
    flat = np.array([[0.0, 120.0], [0.0, 120.0], [60.0, 60.0]])
    with pytest.raises(InvalidInputError, match="backend"):
        solve(_problem(flat), backend="lawnmower")
    assert solve(_problem(flat)).plan is not None
