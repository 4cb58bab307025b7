"""Branching of the team-OPTW branch-and-price: on the weightiest fractional visit, then arcs."""

from __future__ import annotations

import numpy as np

from searchtrack.plan.optw.bp_branching import branch
from searchtrack.plan.optw.bp_master import LPSolution, Master, Restrictions


def _lp(values: list[float]) -> LPSolution:
    return LPSolution(0.0, np.array(values), np.zeros(6), 0.0, np.zeros(0), 0.0)


def _master(paths: list[tuple[int, ...]]) -> Master:
    m = Master(6, 2, True, 1e4)
    m.add(paths, [1.0] * len(paths))
    return m


def test_integral_solution_has_no_children() -> None:
    m = _master([(0, 1, 2, 5), (0, 3, 5)])
    assert branch(m, np.ones(6), Restrictions(), _lp([1.0, 1.0])) is None


def test_branches_on_the_weightiest_fractional_visit() -> None:
    """Visits 1 and 2 are at ½; customer 2's larger profit makes it the one branched on."""
    m = _master([(0, 1, 5), (0, 2, 5), (0, 3, 5)])
    prof = np.array([0.0, 1.0, 5.0, 1.0, 1.0, 0.0])
    kids = branch(m, prof, Restrictions(), _lp([0.5, 0.5, 1.0]))
    assert kids == [Restrictions(forbidden=frozenset({2})), Restrictions(required=frozenset({2}))]


def test_integral_visits_branch_on_an_arc() -> None:
    """Every visit integral but two orders of the same customers at ½: branch on an arc."""
    m = _master([(0, 1, 2, 5), (0, 2, 1, 5)])
    kids = branch(m, np.ones(6), Restrictions(), _lp([0.5, 0.5]))
    assert kids is not None
    forbid, force = kids
    (arc,) = forbid.no_arcs
    assert force.arcs == frozenset({arc})
