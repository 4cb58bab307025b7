"""Route helpers of the exact backends: idle plans, profits, schedules and plan checks."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.optw import validate
from searchtrack.plan.optw.routes import (
    check_plan,
    idle_routes,
    initial_plan,
    routes_profit,
    schedule,
)
from tests.plan.optw.feasible_routes import feasible_routes
from tests.plan.optw.small import cases, hand

CASES = cases()


@pytest.mark.parametrize(("changes", "idle"), [
    ({}, (0, 0)), ({"end": 3, "close": [20, 10, 12, 30]}, (0, 3)), ({"end": None}, (0,))])
def test_idle_routes(changes: dict[str, object], idle: tuple[int, ...]) -> None:
    """One unused route per vehicle: start to end, or just the start for an open end."""
    assert idle_routes(hand(**changes).with_vehicles(3)) == (idle,) * 3


def test_profit_counts_each_customer_once_and_never_the_depot() -> None:
    """Profits 2 + 3.5 are collected; the start's 5 is not, nor a customer twice."""
    inst = hand(profit=[5.0, 2.0, 3.5, 7.0]).with_vehicles(2)
    assert routes_profit(inst, ((0, 1, 2, 0), (0, 0))) == 5.5
    assert routes_profit(inst, ((0, 1, 0), (0, 1, 2, 0))) == 5.5
    assert routes_profit(inst, ((0, 0), (0, 0))) == 0.0


def test_open_end_profit_includes_the_last_visit() -> None:
    """With an open end the last vertex of a route is a customer and is collected."""
    inst = hand(profit=[5.0, 2.0, 3.5, 7.0], end=None)
    assert routes_profit(inst, ((0, 1, 2),)) == 5.5
    assert routes_profit(inst, ((0,),)) == 0.0


def test_schedule_by_hand() -> None:
    """0 → 1 → 2 → 0 starts service at 2 and 6 and is back at 6 + 1 + 8 = 15."""
    assert schedule(hand(), (0, 1, 2, 0)) == (0, 2, 6, 15)
    assert schedule(hand(), [0, 0]) == (0, 0)


def test_schedule_waits_for_a_window() -> None:
    """Arriving at 2 at 6 when it opens at 10 means waiting: service at 10, back at 19."""
    assert schedule(hand(open=[0, 0, 10, 0]), (0, 1, 2, 0)) == (0, 2, 10, 19)


def test_open_end_finishes_after_the_last_service() -> None:
    """With an open end the last time is the end of the last service (6 + 1)."""
    assert schedule(hand(end=None, tmax=15), (0, 1, 2)) == (0, 2, 6, 7)
    assert schedule(hand(end=None, tmax=15), (0,)) == (0, 0)


@pytest.mark.parametrize(("route", "reason"), [
    ((1, 2, 0), "must start at vertex 0"), ((), "must start at vertex 0"),
    ((0, 1, 2), "must end at vertex 0"), ((0,), "must end at vertex 0"),
    ((0, 1, 1, 0), "a customer twice"), ((0, 0, 1, 0), "non-customer"),
    ((0, 2, 1, 0), "reaches vertex 1 at 12, after it closes \\(10\\)"),
    ((0, 3, 0), "reaches vertex 3 at 9, after it closes \\(3\\)")])
def test_schedule_errors_name_the_route_and_the_fault(route: tuple[int, ...], reason: str
                                                      ) -> None:
    """Wrong ends, repeats, non-customers and missed windows raise naming ``route``."""
    with pytest.raises(InvalidInputError, match=reason) as info:
        schedule(hand(), route)
    assert info.value.field == "route"


def test_schedule_refuses_a_late_finish() -> None:
    """Back at 15 when the end closes at 14 is too late."""
    with pytest.raises(InvalidInputError, match="finishes at 15, after 14"):
        schedule(hand(close=[14, 10, 12, 3]), (0, 1, 2, 0))


@pytest.mark.parametrize("name", sorted(CASES))
def test_schedule_agrees_with_the_validator(name: str) -> None:
    """On every feasible route the times are the validator's; on random other routes schedule
    raises exactly when the validator finds a violation."""
    inst = CASES[name]
    for route, times in feasible_routes(inst):
        assert schedule(inst, route) == times
    rng = np.random.default_rng(len(name))
    customers = [int(c) for c in inst.customers]
    tail = () if inst.end is None else (inst.end,)
    for _ in range(40):
        inner = rng.permutation(customers)[: rng.integers(0, len(customers) + 1)]
        route = (inst.start, *(int(v) for v in inner), *tail)
        ok = validate(inst, [route]).feasible
        try:
            schedule(inst, route)
            assert ok, route
        except InvalidInputError:
            assert not ok, route


def test_initial_plan_is_padded_with_idle_routes() -> None:
    """One route for three vehicles comes back as three routes of plain ints."""
    inst = hand().with_vehicles(3)
    plan = initial_plan(inst, [np.array([0, 1, 2, 0])])
    assert plan == ((0, 1, 2, 0), (0, 0), (0, 0))
    assert all(type(v) is int for r in plan for v in r)


def test_initial_plan_errors_name_initial() -> None:
    """Too many routes, or an infeasible one, raise naming ``initial`` and the bad route."""
    inst = hand().with_vehicles(2)
    with pytest.raises(InvalidInputError, match="more than 2 routes") as info:
        initial_plan(inst, [(0, 0)] * 3)
    assert info.value.field == "initial"
    with pytest.raises(InvalidInputError, match=r"route \(0, 2, 1, 0\): reaches vertex 1") as info:
        initial_plan(inst, [(0, 2, 1, 0)])
    assert info.value.field == "initial"


def test_check_plan_wants_every_vehicle_and_disjoint_routes() -> None:
    """A plan must have exactly m routes and no customer on two of them."""
    inst = hand().with_vehicles(2)
    check_plan(inst, ((0, 1, 0), (0, 2, 0)), "plan")
    with pytest.raises(InvalidInputError, match="needs exactly 2 routes") as info:
        check_plan(inst, ((0, 1, 0),), "plan")
    assert info.value.field == "plan"
    with pytest.raises(InvalidInputError, match="customer on two routes"):
        check_plan(inst, ((0, 1, 0), (0, 1, 2, 0)), "plan")
