"""The independent validator: hand-made feasible and infeasible routes."""

from __future__ import annotations

from pathlib import Path

from searchtrack.plan.optw import OPTWInstance, read_optw, validate

DATA = Path(__file__).parents[2] / "data" / "optw"


def _line() -> OPTWInstance:
    # depot 0, customers 1..3 on a line at 10, 20, 30; service 2 each.
    xy = [[0, 0], [10, 0], [20, 0], [30, 0]]
    return OPTWInstance.from_coordinates(
        xy, profit=[0, 5, 6, 7], service=[0, 2, 2, 2], open=[0, 0, 25, 0],
        close=[100, 100, 40, 45], decimals=0, vehicles=2,
    )


def test_feasible_route_schedule_and_profit() -> None:
    """Arrival, wait and start are recomputed; waiting for a window is allowed."""
    inst = _line()
    v = validate(inst, [[0, 1, 2, 3, 0]])
    assert v.feasible, v.violations
    assert v.profit == 18
    sched = v.schedules[0]
    assert [(s.vertex, s.arrival, s.wait, s.start) for s in sched] == [
        (0, 0, 0, 0), (1, 10, 0, 10), (2, 22, 3, 25), (3, 37, 0, 37), (0, 69, 0, 69)]


def test_empty_plans_are_feasible() -> None:
    """No routes, or a depot-to-depot route, collect nothing and violate nothing."""
    inst = _line()
    assert validate(inst, []).feasible
    v = validate(inst, [[0, 0], [0, 0]])
    assert v.feasible and v.profit == 0


def test_window_violation_reported() -> None:
    """Arriving after a window closes is reported with vertex and times."""
    inst = _line()
    v = validate(inst, [[0, 3, 2, 0]])
    assert not v.feasible
    assert any("vertex 2" in p and "closes" in p for p in v.violations)


def test_every_violation_reported() -> None:
    """Duplicate visits, wrong endpoints, too many routes and bad indices are all listed."""
    inst = _line()
    v = validate(inst, [[0, 1, 1, 0], [1, 2], [0, 9], [0, 0]])
    text = " | ".join(v.violations)
    assert "3 routes for 2" not in text and "4 routes for 2 vehicles" in text
    assert "already visited" in text
    assert "starts at 1" in text
    assert "out of range" in text
    assert "does not end at end vertex" in text


def test_late_return_to_depot() -> None:
    """A route that reaches the end vertex after its closing time is infeasible."""
    inst = OPTWInstance.from_coordinates(
        [[0, 0], [10, 0]], profit=[0, 1], service=[0, 5], open=[0, 0], close=[24, 30], decimals=0
    )
    v = validate(inst, [[0, 1, 0]])
    assert not v.feasible and any("finishes at 25" in p for p in v.violations)


def test_open_end_route() -> None:
    """With an open end the route stops at its last visit and needs no end vertex."""
    inst = OPTWInstance.from_coordinates(
        [[0, 0], [10, 0], [20, 0]], profit=[0, 1, 2], service=[0, 0, 0], open=[0, 0, 0],
        close=[100, 100, 100], decimals=0, end=None, tmax=15,
    )
    assert validate(inst, [[0, 1]]).feasible
    v = validate(inst, [[0, 1, 2]])
    assert not v.feasible and any("finishes at 20" in p for p in v.violations)


def test_known_good_c101_route() -> None:
    """A short hand-checked c101 route validates and its profit is the sum of its scores."""
    inst = read_optw(DATA / "c101.txt")
    v = validate(inst, [[0, 20, 24, 25, 27, 29, 30, 28, 26, 23, 22, 21, 0]])
    assert v.profit == sum(inst.profit[[20, 24, 25, 27, 29, 30, 28, 26, 23, 22, 21]])
    assert v.feasible == (not v.violations)
