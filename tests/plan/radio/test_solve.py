"""The registry and ``solve``: names, ``auto``'s stages, determinism per seed, stop requests,
time limits and input checks."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import clear_stop, request_stop
from searchtrack.core.result import Status
from searchtrack.plan.radio import BACKENDS, solve

from .helpers import problem, spread_belief

NAMES = ["auto", "exhaustive", "beam", "greedy", "straight"]


def test_names() -> None:
    """The registered backends, auto first; exhaustive and auto are exact."""
    assert BACKENDS.names() == NAMES
    assert [BACKENDS.get(n).exact for n in NAMES] == [True, True, False, False, False]


def test_auto_answers_with_the_exhaustive_optimum() -> None:
    """auto: beam first, then exhaustive from beam's plan; OPTIMAL with the exhaustive value,
    the stage that answered named, the heuristic's objective in the stats."""
    p = problem(spread_belief(4), horizon=3, plan_particles=30)
    ex = solve(p, backend="exhaustive", time_limit_s=30.0)
    auto = solve(p, time_limit_s=30.0)
    assert auto.status is Status.OPTIMAL and auto.objective == pytest.approx(ex.objective)
    assert auto.backend in ("beam", "exhaustive") and "auto:" in auto.message
    assert "heuristic_objective" in auto.stats


def test_auto_draws_the_look_ahead_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """auto's beam and exhaustive stages score on one look-ahead (one Scorer), and answer what
    exhaustive alone answers."""
    from searchtrack.plan.radio import tree

    built: list[int] = []
    original = tree.Scorer.__init__

    def counting(self: tree.Scorer, *args: object) -> None:
        built.append(1)
        original(self, *args)  # type: ignore[arg-type]

    p = problem(horizon=3)
    alone = solve(p, backend="exhaustive", seed=4, time_limit_s=30.0)  # not the 1 s default:
    assert alone.status is Status.OPTIMAL  # a loaded machine must not stop it early
    monkeypatch.setattr(tree.Scorer, "__init__", counting)
    result = solve(p, backend="auto", seed=4, time_limit_s=30.0)
    assert len(built) == 1 and result.status is Status.OPTIMAL
    assert result.objective == pytest.approx(alone.objective, rel=1e-12)


def test_deterministic_per_seed() -> None:
    """The same seed gives the same plan and rewards; another seed other rewards."""
    p = problem(plan_particles=40)
    a, b = solve(p, seed=3), solve(p, seed=3)
    c = solve(p, seed=4)
    assert a.plan is not None and b.plan is not None and c.plan is not None
    assert np.array_equal(a.plan.path, b.plan.path)
    assert np.array_equal(a.plan.rewards, b.plan.rewards)
    assert not np.array_equal(a.plan.void, c.plan.void)


def test_stop_request_interrupts_with_the_best_plan_so_far() -> None:
    """After a stop request, beam still returns its greedy completion (INTERRUPTED with a
    plan); exhaustive stops before any leaf (INTERRUPTED without one)."""
    p = problem(plan_particles=30)
    request_stop()
    try:
        beam = solve(p, backend="beam")
        ex = solve(p, backend="exhaustive")
    finally:
        clear_stop()
    assert beam.status is Status.INTERRUPTED and beam.plan is not None
    assert beam.objective is not None
    assert ex.status is Status.INTERRUPTED and ex.plan is None


def test_time_limit_is_honoured() -> None:
    """A limit too short for any leaf: no plan and not OPTIMAL, returned at once."""
    p = problem(horizon=3, plan_particles=200)
    res = solve(p, backend="exhaustive", time_limit_s=1e-6)
    assert res.status is Status.NO_SOLUTION and res.plan is None
    assert res.runtime_s < 1.0


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"backend": "astar"}, "backend"), ({"seed": -1}, "seed"), ({"seed": 1.5}, "seed"),
    ({"time_limit_s": 0.0}, "time_limit_s")])
def test_bad_arguments(kwargs: dict[str, object], field: str) -> None:
    """Unknown backend, bad seed or time limit: an error naming it."""
    with pytest.raises(InvalidInputError, match=field):
        solve(problem(), **kwargs)  # type: ignore[arg-type]
