"""The assignment family's validator: every backend's answer passes it on random problems (END
and MI, with and without separation); a wrong END, an index out of range, a colliding pair and a
bound below the objective come back as ERROR."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.plan.assign import BACKENDS, Assignment, solve
from searchtrack.plan.assign.validate import answer_problems

from .helpers import random_problem


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("objective", ["end", "mi"])
def test_every_backend_passes(seed: int, objective: str) -> None:
    """No backend's answer is rejected."""
    rng = np.random.default_rng(seed)
    problem = random_problem(rng, robots=3, actions=3, steps=1, particles=20,
                             objective=objective, separation=10.0 if seed % 2 else 0.0)
    for name in BACKENDS.names():
        if BACKENDS.get(name).supports(problem) is not None:
            continue
        result = solve(problem, backend=name, time_limit_s=5.0)
        assert result.status is not Status.ERROR, (name, result.message)


def test_wrong_answers_are_rejected() -> None:
    """Each corruption is named and solve's registry turns it into ERROR."""
    rng = np.random.default_rng(7)
    problem = random_problem(rng, robots=2, actions=3, steps=2, particles=30)
    good = solve(problem, backend="brute_force")
    assert good.plan is not None and good.objective is not None
    assert answer_problems(problem, good) == []
    lie = dataclasses.replace(good, objective=good.objective * (1 + 1e-6))
    assert any("END" in p for p in answer_problems(problem, lie))
    assert BACKENDS.validated(problem, lie).status is Status.ERROR
    low = dataclasses.replace(good, bound=good.objective - 1e-3)
    assert any("bound" in p for p in answer_problems(problem, low))
    outside = dataclasses.replace(good, plan=Assignment((0, 9), good.plan.poses))
    assert any("action 9" in p for p in answer_problems(problem, outside))
    crowded = dataclasses.replace(problem, min_separation_m=1e6)
    assert any("apart" in p for p in answer_problems(crowded, good))
