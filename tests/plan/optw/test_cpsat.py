"""Tests for the CP-SAT backend of the (team) OPTW."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.optw import OPTWInstance, read_optw, validate
from searchtrack.plan.optw.cpsat import Formulation, solve_cpsat
from tests.plan.optw.catalogue import brute_force, catalogue

DATA = Path(__file__).resolve().parents[3] / "searchtrack" / "data" / "optw"


@pytest.mark.parametrize("name", sorted(catalogue()))
def test_catalogue_optimum(name: str) -> None:
    """CP-SAT proves the brute-force optimum of every catalogue instance with a valid plan."""
    inst = catalogue()[name]
    best = brute_force(inst)
    res = solve_cpsat(inst, time_limit_s=20, workers=1)
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
    assert res.bound is not None and res.bound >= best - 1e-9
    assert res.bound == pytest.approx(best, abs=1e-5)


@pytest.mark.parametrize(
    "form",
    [
        Formulation(budget=False, intervals=False, incompatibility=False, ordering=False,
                    single_share=0.0),
        Formulation(ordering=False, routes_for_single=False, linearization_level=1,
                    probing_level=0, relation_cut_size=8),
    ],
)
@pytest.mark.parametrize("name", ["euclid-m1", "asym-start-end-m1", "asym-open-m2", "euclid-m3"])
def test_formulation_variants_agree(name: str, form: Formulation) -> None:
    """Every switchable strengthening leaves the optimum unchanged."""
    inst = catalogue()[name]
    res = solve_cpsat(inst, time_limit_s=20, workers=1, formulation=form)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(brute_force(inst), abs=1e-9)


def test_initial_plan_is_hinted_and_kept() -> None:
    """A feasible initial plan is accepted and the result is at least as good."""
    inst = catalogue()["euclid-m2"]
    first = solve_cpsat(inst, time_limit_s=10, workers=1)
    assert first.plan is not None
    again = solve_cpsat(inst, time_limit_s=10, workers=1, initial=first.plan)
    assert again.status is Status.OPTIMAL
    assert again.objective == pytest.approx(first.objective)


def test_infeasible_initial_plan_is_rejected() -> None:
    """An initial plan that breaks a window is refused, naming the field."""
    inst = catalogue()["euclid-m1"]
    with pytest.raises(InvalidInputError, match="initial"):
        solve_cpsat(inst, initial=((0, 1, 2, 3, 4, 5, 6, 7, 0),))


def test_nothing_reachable_is_optimal_and_empty() -> None:
    """With every window closed, the answer is OPTIMAL, profit 0, all vehicles idle."""
    inst = catalogue()["closed"].with_vehicles(2)
    res = solve_cpsat(inst, time_limit_s=5)
    assert res.status is Status.OPTIMAL
    assert res.objective == 0.0 and res.bound == 0.0
    assert res.plan == ((0, 0), (0, 0))


def test_seeded_single_worker_is_deterministic() -> None:
    """Two runs with one worker and the same seed return the same plan."""
    inst = catalogue()["asym-m2"]
    a = solve_cpsat(inst, time_limit_s=10, seed=3, workers=1)
    b = solve_cpsat(inst, time_limit_s=10, seed=3, workers=1)
    assert a.plan == b.plan


def test_c101_returns_a_valid_plan() -> None:
    """On Solomon c101 a short run returns a plan that the validator accepts."""
    inst = read_optw(DATA / "c101.txt")
    res = solve_cpsat(inst, time_limit_s=20)
    assert res.status in (Status.OPTIMAL, Status.FEASIBLE)
    assert res.plan is not None
    check = validate(inst, res.plan)
    assert check.feasible, check.violations
    assert check.profit == res.objective
    assert res.bound is not None and res.bound + 1e-9 >= 320  # 320 is the proven optimum
    assert res.objective is not None and res.objective <= 320


def test_time_limit_is_honoured() -> None:
    """A one-second limit on a hard team instance returns within a coarse margin."""
    inst: OPTWInstance = read_optw(DATA / "rc101.txt", vehicles=3)
    res = solve_cpsat(inst, time_limit_s=1.0)
    assert res.runtime_s < 3.0
    if res.plan is not None:
        assert validate(inst, res.plan).feasible


@pytest.mark.parametrize("limit", [0, -1.0, math.nan, "10"])
def test_bad_time_limit_raises(limit: object) -> None:
    """A non-positive or non-numeric time limit is an InvalidInputError."""
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve_cpsat(catalogue()["euclid-m1"], time_limit_s=limit)  # type: ignore[arg-type]


def test_bad_workers_raises() -> None:
    """Zero workers is an InvalidInputError naming the field."""
    with pytest.raises(InvalidInputError, match="workers"):
        solve_cpsat(catalogue()["euclid-m1"], workers=0)
