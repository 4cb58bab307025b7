"""Tests for the reference integer program (thesis (5.17)–(5.26)) of the (team) OPTW."""

from __future__ import annotations

import math

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.optw import validate
from searchtrack.plan.optw.mip import solve_mip
from tests.plan.optw.catalogue import brute_force, catalogue


@pytest.mark.parametrize("name", sorted(catalogue()))
def test_catalogue_optimum(name: str) -> None:
    """The MIP proves the brute-force optimum of every catalogue instance with a valid plan."""
    inst = catalogue()[name]
    best = brute_force(inst)
    res = solve_mip(inst, time_limit_s=20)
    if best == -math.inf:
        assert res.status is Status.INFEASIBLE
        assert res.plan is None
        return
    assert res.status is Status.OPTIMAL, res.message
    assert res.plan is not None and len(res.plan) == inst.vehicles
    check = validate(inst, res.plan)
    assert check.feasible, check.violations
    assert res.objective == pytest.approx(best, abs=1e-9)
    assert check.profit == pytest.approx(res.objective, abs=1e-9)
    assert res.bound is not None and res.bound == pytest.approx(best, abs=1e-5)


def test_initial_plan_is_accepted() -> None:
    """A feasible initial plan is used as a hint and the optimum is still reached."""
    inst = catalogue()["euclid-start-end-m2"]
    first = solve_mip(inst, time_limit_s=10)
    assert first.plan is not None
    again = solve_mip(inst, time_limit_s=10, initial=first.plan)
    assert again.status is Status.OPTIMAL
    assert again.objective == pytest.approx(first.objective)


def test_short_initial_plan_is_padded() -> None:
    """An initial plan with fewer routes than vehicles is completed with idle routes."""
    inst = catalogue()["euclid-m2"]
    res = solve_mip(inst, time_limit_s=10, initial=((0, 0),))
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(brute_force(inst))


def test_infeasible_initial_plan_is_rejected() -> None:
    """An initial plan with too many routes is refused, naming the field."""
    inst = catalogue()["euclid-m2"]
    with pytest.raises(InvalidInputError, match="initial"):
        solve_mip(inst, initial=((0, 0),) * 3)


def test_nothing_reachable_is_optimal_and_empty() -> None:
    """With every window closed, the answer is OPTIMAL with profit 0 and idle routes."""
    res = solve_mip(catalogue()["closed"], time_limit_s=5)
    assert res.status is Status.OPTIMAL
    assert res.objective == 0.0
    assert res.plan == ((0, 0),)


def test_time_limit_is_honoured() -> None:
    """A short limit on a larger instance returns within a coarse margin."""
    from pathlib import Path

    from searchtrack.plan.optw import read_optw

    data = Path(__file__).resolve().parents[3] / "searchtrack" / "data" / "optw"
    inst = read_optw(data / "rc101.txt", vehicles=2)
    res = solve_mip(inst, time_limit_s=2.0)
    assert res.runtime_s < 6.0
    assert res.status in (Status.OPTIMAL, Status.FEASIBLE, Status.NO_SOLUTION)
    if res.plan is not None:
        assert validate(inst, res.plan).feasible


@pytest.mark.parametrize("limit", [0, -5, math.inf * 0])
def test_bad_time_limit_raises(limit: float) -> None:
    """A non-positive or NaN time limit is an InvalidInputError."""
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve_mip(catalogue()["euclid-m1"], time_limit_s=limit)
