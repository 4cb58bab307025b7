"""Branching of the team-OPTW branch-and-price: on the weightiest fractional visit, then arcs;
strong branching on the pooled master."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw.bp_branching import branch, candidates, pooled_value, strong
from searchtrack.plan.optw.bp_master import LPSolution, Master, Restrictions


def _lp(values: list[float]) -> LPSolution:
    return LPSolution(0.0, np.array(values), np.zeros(6), 0.0, np.zeros(0), 0.0)


def _master(paths: list[tuple[int, ...]]) -> Master:
    m = Master(6, 2, True, 1e4)
    m.add(paths, [1.0] * len(paths))
    return m


def test_integral_solution_has_no_children() -> None:
    m = _master([(0, 1, 2, 5), (0, 3, 5)])
    assert branch(m, np.ones(6), Restrictions(), _lp([1.0, 1.0])) == (None, 0)


def test_branches_on_the_weightiest_fractional_visit() -> None:
    """Visits 1 and 2 are at ½; customer 2's larger profit makes it the one branched on."""
    m = _master([(0, 1, 5), (0, 2, 5), (0, 3, 5)])
    prof = np.array([0.0, 1.0, 5.0, 1.0, 1.0, 0.0])
    kids, probes = branch(m, prof, Restrictions(), _lp([0.5, 0.5, 1.0]))
    assert probes == 0
    assert kids == [Restrictions(forbidden=frozenset({2})), Restrictions(required=frozenset({2}))]


def test_integral_visits_branch_on_an_arc() -> None:
    """Every visit integral but two orders of the same customers at ½: branch on an arc."""
    m = _master([(0, 1, 2, 5), (0, 2, 1, 5)])
    kids, _ = branch(m, np.ones(6), Restrictions(), _lp([0.5, 0.5]))
    assert kids is not None
    forbid, force = kids
    (arc,) = forbid.no_arcs
    assert force.arcs == frozenset({arc})


def test_candidates_are_ranked_and_capped() -> None:
    """Three fractional visits: ranked by min(y, 1 − y) × profit, at most ``most`` of them."""
    m = _master([(0, 1, 5), (0, 2, 5), (0, 3, 5), (0, 4, 5)])
    prof = np.array([0.0, 1.0, 5.0, 3.0, 9.0, 0.0])
    lp = _lp([0.5, 0.5, 0.5, 1.0])
    found = candidates(m, prof, Restrictions(), lp, 5)
    assert [f[0].forbidden for f in found] == [frozenset({2}), frozenset({3}), frozenset({1})]
    assert len(candidates(m, prof, Restrictions(), lp, 2)) == 2


def _star() -> tuple[Master, Restrictions]:
    """Two vehicles, customers 1–4, the pairs of 1, 2, 3 worth 10 and (4, 1) worth 6; the
    parent forbids the arc 3 → 2. The master's optimum, 16.5, takes each pair of the triangle
    and the single route to 4 at ½."""
    m = Master(6, 2, True, 1e4)
    paths = [(0, 1, 5), (0, 2, 5), (0, 3, 5), (0, 4, 5), (0, 1, 2, 5), (0, 2, 3, 5), (0, 1, 3, 5),
             (0, 4, 1, 5), (0, 3, 2, 5)]
    m.add(paths, [4.0, 4.0, 4.0, 3.0, 10.0, 10.0, 10.0, 6.0, 9.0])
    return m, Restrictions(no_arcs=frozenset({(3, 2)}))


def test_pooled_value_probes_a_child_and_restores_the_parent() -> None:
    """A probe's value is the master's optimum with the child's decision added (checked against
    a full restriction to the child), and the master is left as it was under the parent."""
    m, parent = _star()
    m.restrict(parent)
    before = (m.upper.copy(), set(m.required))
    lp = m.solve(10.0)
    assert lp is not None
    for child in (parent.child(forbid=1), parent.child(require=4), parent.child(no_arc=(1, 2)),
                  parent.child(arc=(1, 3))):
        z = pooled_value(m, parent, child, 10.0)
        assert np.array_equal(m.upper, before[0]) and m.required == before[1]
        m.restrict(child)
        full = m.solve(10.0)
        m.restrict(parent)
        assert full is not None and z == pytest.approx(full.objective)
    again = m.solve(10.0)
    assert again is not None and again.objective == pytest.approx(lp.objective)


def test_strong_picks_the_largest_product_of_falls() -> None:
    """Candidates on customers 1, 2 and 4: forbidding 1 or 2 costs 3.5 but requiring them
    nothing, while both children of 4 fall (1.5 and 0.5), so 4 wins although ranked last; each
    fall is capped at the parent's distance to the incumbent."""
    m, parent = _star()
    m.restrict(parent)
    lp = m.solve(10.0)
    assert lp is not None
    found = [(parent.child(forbid=i), parent.child(require=i)) for i in (1, 2, 4)]
    falls = []
    for pair in found:
        zs = [pooled_value(m, parent, c, 10.0) for c in pair]
        falls.append([lp.objective - z for z in zs if z is not None])
    assert lp.objective == pytest.approx(16.5)
    k, solved = strong(m, parent, found, lp.objective, -math.inf, Deadline(10.0))
    assert solved == 6 and k == 2
    scores = [max(a, 1e-6) * max(b, 1e-6) for a, b in falls]
    assert k == int(np.argmax(scores))
    floor = lp.objective - 1.0  # falls capped at 1: the first ranked of equal scores wins
    k, _ = strong(m, parent, found, lp.objective, floor, Deadline(10.0))
    capped = [min(max(a, 1e-6), 1.0) * min(max(b, 1e-6), 1.0) for a, b in falls]
    assert k == int(np.argmax(capped)) == 2
    assert strong(m, parent, found[:1], lp.objective, floor, Deadline(10.0)) == (0, 0)
