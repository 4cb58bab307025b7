"""The branch-and-price master: LP duals, branching bounds, artificial rows, cut rows."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.plan.optw.bp_master import Master, Restrictions

# core graph of two customers: source 0, customers 1 and 2, sink 3
PATHS = [(0, 1, 3), (0, 2, 3), (0, 1, 2, 3), (0, 3)]
PROFITS = [5.0, 3.0, 7.0, 0.0]


def _master(vehicles: int = 1, empty_ok: bool = True) -> Master:
    m = Master(4, vehicles, empty_ok, penalty=1e3)
    m.add(PATHS, PROFITS)
    return m


@pytest.mark.parametrize("vehicles", [1, 2])
def test_duals_close_the_duality_gap(vehicles: int) -> None:
    """Σ π + m μ equals the LP optimum and no column has a positive reduced profit."""
    m = _master(vehicles)
    lp = m.solve(10.0)
    assert lp is not None
    assert lp.objective == pytest.approx(7.0 if vehicles == 1 else 8.0)
    assert float(lp.pi.sum()) + vehicles * lp.mu == pytest.approx(lp.objective)
    assert np.all(lp.pi >= -1e-9) and lp.mu >= -1e-9
    for path, c in zip(PATHS, PROFITS, strict=True):
        assert c - sum(lp.pi[i] for i in path[1:-1]) - lp.mu <= 1e-9


def test_a_required_row_keeps_a_negative_dual() -> None:
    """Customer 2 required, worth 1, while customer 1 is worth 5 and one vehicle serves either:
    π_2 = 1 − μ < 0 is kept (an equality row's dual has no sign), the free row's π_1 is ≥ 0,
    and Σ π + m μ still equals the LP optimum."""
    m = Master(4, 1, True, penalty=1e3)
    m.add([(0, 1, 3), (0, 2, 3), (0, 3)], [5.0, 1.0, 0.0])
    m.restrict(Restrictions(required=frozenset({2})))
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(1.0)
    assert lp.pi[2] < 0 and lp.pi[1] >= 0 and lp.mu >= 5.0 - lp.pi[1] - 1e-9
    assert float(lp.pi.sum()) + lp.mu == pytest.approx(lp.objective)


def test_known_columns_are_not_added_twice() -> None:
    """Adding a column already in the pool is a no-op; each column keeps its position."""
    m = _master()
    assert m.add([PATHS[0], (0, 2, 1, 3)], [5.0, 6.0]) == 1
    assert m.size == len(PATHS) + 1
    assert m.index(PATHS[0]) == 0 and m.index((0, 2, 1, 3)) == len(PATHS)
    assert all(m.paths[m.index(p)] == p for p in PATHS)


def test_restrict_forbids_columns_and_requires_rows() -> None:
    """A forbidden customer removes its columns; a required one forces its row to 1."""
    m = _master()
    m.restrict(Restrictions(forbidden=frozenset({1})))
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(3.0)
    m.restrict(Restrictions(required=frozenset({2}), no_arcs=frozenset({(1, 2)})))
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(3.0)
    assert m.visits(lp.values)[2] == pytest.approx(1.0)
    m.restrict(Restrictions())
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(7.0)


def test_unservable_required_row_uses_the_artificial() -> None:
    """A required customer that no column serves makes the artificial variable positive."""
    m = Master(4, 1, True, penalty=1e3)
    m.add([(0, 1, 3), (0, 3)], [5.0, 0.0])
    m.restrict(Restrictions(required=frozenset({2})))
    lp = m.solve(10.0)
    assert lp is not None and lp.artificial == pytest.approx(1.0)
    assert lp.objective < 0


def test_empty_route_infeasible_makes_the_fleet_row_an_equality() -> None:
    """Without the empty route, exactly m columns must be chosen."""
    m = Master(4, 2, False, penalty=1e3)
    m.add(PATHS[:3], PROFITS[:3])
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(8.0)
    assert float(lp.values.sum()) == pytest.approx(2.0)


@pytest.mark.parametrize(("restr", "allowed"), [
    (Restrictions(no_arcs=frozenset({(1, 2)})), [True, True, False, True]),
    (Restrictions(arcs=frozenset({(1, 2)})), [False, False, True, True]),
    (Restrictions(arcs=frozenset({(0, 2)})), [True, True, False, True]),
    (Restrictions(arcs=frozenset({(2, 3)})), [True, True, True, True]),
    (Restrictions(forbidden=frozenset({2})), [True, False, False, True]),
])
def test_restrictions_allow(restr: Restrictions, allowed: list[bool]) -> None:
    """A forced arc i → j is the only way out of i and into j (not out of the source or into
    the sink); a forbidden arc or customer rules out the paths that use it."""
    assert [restr.allows(p, 0, 3) for p in PATHS] == allowed


def test_arc_flows_and_visits() -> None:
    """Arc flows and visits sum the column values."""
    m = _master()
    values = np.array([0.5, 0.5, 0.5, 0.0])
    assert m.visits(values)[1:3].tolist() == [1.0, 1.0]
    assert m.arc_flows(values)[(0, 1)] == pytest.approx(1.0)


def test_a_troubled_solve_is_repeated_from_a_fresh_factorisation(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """When HiGHS ends a solve without an optimum the master solves the same LP again from a
    fresh factorisation and gives the same optimum, duals and branching bounds, and keeps
    working (adding columns, restricting)."""
    import highspy

    m = _master(2, empty_ok=False)
    m.restrict(Restrictions(required=frozenset({2})))
    before = m.solve(10.0)
    real = Master._run
    calls = []

    def troubled(self: Master, seconds: float) -> highspy.HighsModelStatus:
        calls.append(seconds)
        if len(calls) == 1:
            return highspy.HighsModelStatus.kSolveError
        return real(self, seconds)

    monkeypatch.setattr(Master, "_run", troubled)
    after = m.solve(10.0)
    assert len(calls) == 2 and m.failures == 1
    assert before is not None and after is not None
    assert after.objective == pytest.approx(before.objective)
    np.testing.assert_allclose(after.pi, before.pi, atol=1e-9)
    assert after.mu == pytest.approx(before.mu)
    np.testing.assert_allclose(after.values, before.values, atol=1e-9)
    m.add([(0, 2, 1, 3)], [9.0])
    m.restrict(Restrictions())
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(9.0)  # (0, 2, 1, 3) and the empty route


def test_an_unfinished_solve_gives_no_solution() -> None:
    """HiGHS stopped before the optimum (here by an iteration limit of 0) on both tries: no
    solution."""
    m = _master(2)
    m.highs.setOptionValue("simplex_iteration_limit", 0)
    assert m.solve(10.0) is None
    assert m.failures == 1  # tried once more: only the time limit is not retried


def test_cut_rows_take_the_coefficients_and_give_duals() -> None:
    """A subset-row cut on {1, 2, 3} over three pair routes at ½ each: the LP obeys it, gives it
    a non-negative dual, and later columns get their coefficients too."""
    from searchtrack.plan.optw.bp_cuts import SubsetRowCut

    m = Master(5, 3, True, penalty=1e3)
    m.add([(0, 1, 2, 4), (0, 2, 3, 4), (0, 1, 3, 4)], [2.0, 2.0, 2.0])
    first = m.solve(10.0)
    assert first is not None and first.objective == pytest.approx(3.0)  # each at ½
    cut = SubsetRowCut(frozenset({1, 2, 3}), frozenset({1, 2, 3}))
    assert m.add_cuts([cut]) == 1
    lp = m.solve(10.0)
    assert lp is not None and lp.objective == pytest.approx(2.0)
    assert lp.sigma.shape == (1,) and lp.sigma[0] >= 0
    m.add([(0, 3, 1, 4)], [2.5])
    assert m.cut_cost((0, 3, 1, 4), np.array([1.5])) == 1.5
    last = m.solve(10.0)
    assert last is not None and last.objective == pytest.approx(2.5)
