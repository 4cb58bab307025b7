"""Reachability bounds: hand-computed earliest and latest starts, sound on every feasible route."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.plan.optw.reach import reach
from tests.plan.optw.feasible_routes import feasible_routes
from tests.plan.optw.small import cases, hand

NEVER = np.iinfo(np.int64).max // 4

CASES = cases()


def test_hand_instance_bounds() -> None:
    """Earliest starts go through the shortcut (vertex 2 at 6, not 8); latest starts still reach
    the end by 20 (vertex 2 by 20 − 8 − 1 = 11); vertex 3 can never be reached in time."""
    r = reach(hand())
    np.testing.assert_array_equal(r.earliest, [0, 2, 6, NEVER])
    np.testing.assert_array_equal(r.latest, [20, 10, 11, 3])
    assert r.vertex_ok.tolist() == [False, True, True, False]
    assert r.useful.tolist() == [1, 2]


def test_hand_instance_arcs() -> None:
    """Only 1 → 2 (2 + 1 + 3 ≤ 11) and 2 → 1 (6 + 1 + 3 ≤ 10) are kept: arcs touching the start
    and end vertex are left to the arc graph, and vertex 3 is useless."""
    ok = reach(hand()).arc_ok
    assert {(int(a), int(b)) for a, b in zip(*np.nonzero(ok), strict=True)} == {(1, 2), (2, 1)}


def test_open_end_latest_starts_come_from_the_budget() -> None:
    """With an open end and tmax 15 a customer's latest start is min(close, 15 − service); the
    start may then lead to customers."""
    r = reach(hand(end=None, tmax=15))
    np.testing.assert_array_equal(r.latest, [15, 10, 12, 3])
    assert r.arc_ok[0, 1] and r.arc_ok[0, 2] and not r.arc_ok[1, 0]


def test_a_customer_that_cannot_get_back_is_useless() -> None:
    """Reachable by its window but too far from the end to return by the deadline: not useful."""
    r = reach(hand(close=[20, 10, 12, 30], travel=[[0, 2, 8, 9], [2, 0, 3, 9], [8, 3, 0, 9],
                                                    [15, 15, 15, 0]]))
    assert r.earliest[3] == 9 and r.latest[3] < 9
    assert not r.vertex_ok[3]


def test_distinct_end_vertex_is_never_a_customer() -> None:
    """With start 0 and end 3, vertex 3 only ends routes: no arc leaves it or enters the start."""
    r = reach(hand(end=3, close=[20, 10, 12, 25]))
    assert not r.vertex_ok[3] and not r.arc_ok[3].any() and not r.arc_ok[:, 0].any()
    assert r.latest[3] == 25


@pytest.mark.parametrize("name", sorted(CASES))
def test_bounds_hold_on_every_feasible_route(name: str) -> None:
    """On every feasible route each customer is useful and served within [earliest, latest], and
    every customer-to-customer arc it drives is kept."""
    inst = CASES[name]
    r = reach(inst)
    inner_end = None if inst.end is None else -1
    for route, times in feasible_routes(inst):
        inner = route[1:inner_end]
        for v, t in zip(inner, times[1:], strict=False):
            assert r.vertex_ok[v], (route, v)
            assert r.earliest[v] <= t <= r.latest[v], (route, v, t)
        for a, b in itertools.pairwise(inner):
            assert r.arc_ok[a, b], (route, a, b)


@pytest.mark.parametrize("name", sorted(CASES))
def test_every_useful_customer_is_near_a_feasible_route(name: str) -> None:
    """The bounds are not vacuous: a customer judged useful is reachable in time from the start
    (earliest ≤ close) and on these small instances lies on some feasible route."""
    inst = CASES[name]
    r = reach(inst)
    visited = {v for route, _ in feasible_routes(inst) for v in route} - {inst.start, inst.end}
    assert np.all(r.earliest[r.useful] <= inst.close[r.useful])
    assert set(r.useful.tolist()) == visited
