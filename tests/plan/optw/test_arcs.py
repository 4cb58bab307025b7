"""The arc graph and gap tables: hand-computed arcs, and validity on every feasible route."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse.csgraph import floyd_warshall

from searchtrack.plan.optw import OPTWInstance
from searchtrack.plan.optw.arcs import NEVER, ArcGraph, arc_graph, follow_gaps, shortest_gaps
from tests.plan.optw.feasible_routes import feasible_routes
from tests.plan.optw.small import cases, hand

CASES = cases()


def _arcs(g: ArcGraph) -> dict[tuple[int, int], tuple[int, int]]:
    """Arc (tail, head) → (δ, weight)."""
    return {(int(a), int(b)): (int(d), int(w)) for a, b, d, w in
            zip(g.tails, g.heads, g.delta, g.weight, strict=True)}


def test_hand_graph() -> None:
    """Customers 1 and 2 become nodes 1 and 2 (3 is dropped); δ is service + travel, and the
    depot's latest finish is the 20 of its window."""
    g = arc_graph(hand())
    assert g.vertices.tolist() == [1, 2] and g.size == 3 and g.empty_ok
    assert g.earliest.tolist() == [0, 2, 6] and g.latest.tolist() == [20, 10, 11]
    assert _arcs(g) == {(0, 1): (2, 2), (0, 2): (8, 8), (1, 2): (4, 4), (2, 1): (4, 4),
                        (1, 0): (3, 3), (2, 0): (9, 9)}


def test_waiting_forced_by_a_window_counts_in_the_weight() -> None:
    """Customer 2 opens at 10: driving there from the start takes 8, so the arc weighs 10."""
    g = arc_graph(hand(open=[0, 0, 10, 0]))
    arcs = _arcs(g)
    assert g.earliest.tolist() == [0, 2, 10]
    assert arcs[(0, 2)] == (8, 10) and arcs[(1, 2)] == (4, 4)


def test_open_end_finishes_at_the_last_service() -> None:
    """With an open end and tmax 15, arcs into the depot cost the service only, and the latest
    finish is that of the latest last service (12 + 1 = 13)."""
    g = arc_graph(hand(end=None, tmax=15))
    arcs = _arcs(g)
    assert arcs[(1, 0)] == (1, 1) and arcs[(2, 0)] == (1, 1)
    assert g.latest[0] == 13


def test_empty_route_that_misses_the_deadline_is_flagged() -> None:
    """Start 0, end 3 at distance 9, deadline 8: not even the empty route is feasible."""
    g = arc_graph(hand(end=3, close=[20, 10, 12, 8]))
    assert not g.empty_ok
    assert arc_graph(hand(end=3, close=[20, 10, 12, 9])).empty_ok


def test_nothing_reachable_leaves_only_the_depot() -> None:
    """When every window closes too early the graph has the depot and no arcs."""
    g = arc_graph(hand(close=[20, 1, 1, 1]))
    assert g.size == 1 and g.tails.size == 0 and g.empty_ok


def test_hand_gaps() -> None:
    """E[1, 2] = 2 + 1 + 3 = 6 and E[2, 1] = 6 + 1 + 3 = 10; D is service + travel."""
    inst = hand()
    g = arc_graph(inst)
    e = follow_gaps(inst, g)
    assert e.tolist() == [[NEVER] * 3, [NEVER, NEVER, 6], [NEVER, 10, NEVER]]
    assert shortest_gaps(inst, g).tolist() == [[1, 4], [4, 1]]


def test_follow_gaps_respect_windows_on_the_way() -> None:
    """When 1 closes at 8, it cannot follow 2 (earliest 6, then 6 + 1 + 3 = 10 > 8): E[2, 1] is
    NEVER while E[1, 2] stays 6."""
    inst = hand(close=[20, 8, 12, 3])
    e = follow_gaps(inst, arc_graph(inst))
    assert e[1, 2] == 6 and e[2, 1] == NEVER


def test_shortest_gaps_equal_floyd_warshall() -> None:
    """On a random non-metric matrix the gaps are scipy's all-pairs shortest paths of s + t."""
    rng = np.random.default_rng(5)
    n = 7
    travel = rng.integers(1, 50, size=(n, n))
    np.fill_diagonal(travel, 0)
    inst = OPTWInstance(travel=travel, service=rng.integers(1, 5, size=n),
                        profit=np.ones(n), open=np.zeros(n, int), close=np.full(n, 10_000))
    g = arc_graph(inst)
    assert g.vertices.tolist() == list(range(1, n))
    v = g.vertices
    weights = (inst.service[v][:, None] + inst.travel[np.ix_(v, v)]).astype(float)
    np.fill_diagonal(weights, 0.0)
    expected = floyd_warshall(weights, directed=True)
    got = shortest_gaps(inst, g).astype(float)
    off = ~np.eye(v.size, dtype=bool)
    np.testing.assert_array_equal(got[off], expected[off])


@pytest.mark.parametrize("name", sorted(CASES))
def test_graph_and_gaps_hold_on_every_feasible_route(name: str) -> None:
    """Every feasible route uses only kept arcs, serves each node inside its [earliest, latest],
    leaves at least δ between services, meets the gap tables and the duration budget
    Σ weight ≤ latest[0] − earliest[0]."""
    inst = CASES[name]
    g = arc_graph(inst)
    arcs = _arcs(g)
    node = {int(v): j for j, v in enumerate(g.vertices, start=1)}
    e, d = follow_gaps(inst, g), shortest_gaps(inst, g)
    inner_end = None if inst.end is None else -1
    for route, times in feasible_routes(inst):
        inner = route[1:inner_end]
        nodes = [0, *(node[v] for v in inner), 0]
        starts = [g.earliest[0], *times[1:len(inner) + 1], times[-1]]
        budget = 0
        for k in range(len(nodes) - 1):
            a, b = nodes[k], nodes[k + 1]
            if a == b == 0:
                continue  # the empty route
            assert (a, b) in arcs, (route, a, b)
            delta, weight = arcs[(a, b)]
            assert starts[k + 1] - starts[k] >= delta
            budget += weight
        assert budget <= g.latest[0] - g.earliest[0], route
        for j, t in zip(nodes[1:-1], starts[1:-1], strict=True):
            assert g.earliest[j] <= t <= g.latest[j]
        assert times[-1] <= g.latest[0]
        for p in range(1, len(nodes) - 1):
            for q in range(p + 1, len(nodes) - 1):
                a, b = nodes[p], nodes[q]
                assert e[a, b] <= starts[q], (route, a, b)
                assert starts[q] - starts[p] >= d[a - 1, b - 1], (route, a, b)
