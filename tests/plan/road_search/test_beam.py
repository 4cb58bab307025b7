"""Beam search: optimal when nothing is pruned, width 1 is greedy, bounds stay valid, UAVs
re-plan against each other, bad options are refused."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.road_search.beam import solve_beam
from searchtrack.plan.road_search.exhaustive import solve_exhaustive
from searchtrack.plan.road_search.greedy import solve_greedy

from .helpers import grid_roads, random_problem, random_roads


@pytest.mark.parametrize("seed", range(4))
def test_wide_beam_is_optimal_for_one_uav(seed: int) -> None:
    """A beam wider than the tree prunes nothing: OPTIMAL, the exhaustive objective."""
    p = random_problem(random_roads(seed), np.random.default_rng(seed), lookahead=3)
    res = solve_beam(p, width=10_000)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(solve_exhaustive(p).objective, rel=1e-12)


@pytest.mark.parametrize("seed", range(4))
def test_width_one_is_the_greedy_plan(seed: int) -> None:
    """Without per-length values a one-path beam picks the best Eq. 21 edge at each node."""
    p = random_problem(grid_roads(), np.random.default_rng(seed), lookahead=4)
    beam, greedy = solve_beam(p, width=1), solve_greedy(p)
    assert beam.plan == greedy.plan


@pytest.mark.parametrize("seed", range(4))
def test_narrow_beam_bound_is_valid(seed: int) -> None:
    """A pruned beam is FEASIBLE (unless it meets the bound) and never above the optimum; its
    bound is never below it."""
    p = random_problem(grid_roads(), np.random.default_rng(seed), uavs=1 + seed % 2,
                       lookahead=4)
    res, best = solve_beam(p, width=2), solve_exhaustive(p)
    assert res.status in (Status.FEASIBLE, Status.OPTIMAL)
    assert best.objective is not None and res.objective is not None and res.bound is not None
    assert res.objective <= best.objective + 1e-12 <= res.bound + 2e-12
    if res.status is Status.OPTIMAL:
        assert res.objective == pytest.approx(best.objective, rel=1e-9)


def test_re_planning_never_hurts() -> None:
    """More passes (UAVs re-planning against each other) never lower the objective."""
    for seed in range(4):
        p = random_problem(grid_roads(), np.random.default_rng(seed), uavs=3, lookahead=3)
        one, three = solve_beam(p, passes=1), solve_beam(p, passes=3)
        assert one.objective is not None and three.objective is not None
        assert three.objective >= one.objective - 1e-12


@pytest.mark.parametrize(("kwargs", "field"), [({"width": 0}, "width"), ({"passes": 0}, "passes")])
def test_bad_options(kwargs: dict[str, int], field: str) -> None:
    """Width and passes must be positive integers."""
    p = random_problem(grid_roads(), np.random.default_rng(0), lookahead=1)
    with pytest.raises(InvalidInputError) as err:
        solve_beam(p, **kwargs)  # type: ignore[arg-type]
    assert err.value.field == field
