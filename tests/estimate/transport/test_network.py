"""The network simplex backend: EMD problems posed as min-cost flows."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from searchtrack.core.result import Status
from searchtrack.estimate.transport import GraphProblem, TransportProblem, emd
from searchtrack.estimate.transport.network import solve_graph_network, solve_transport_network


def test_time_limit_gives_no_solution_not_a_wrong_one() -> None:
    """A time limit too short for any pivot returns NO_SOLUTION without a plan."""
    rng = np.random.default_rng(0)
    result = emd(rng.random(200), rng.random(200), rng.random((200, 200)), backend="network",
                 time_limit_s=1e-9)
    assert result.status is Status.NO_SOLUTION and result.plan is None


def _path(lengths: list[float]) -> sp.csr_array:
    """An undirected path whose consecutive nodes are ``lengths`` apart."""
    n = len(lengths) + 1
    i = np.arange(n - 1)
    ell = np.asarray(lengths, dtype=float)
    return sp.csr_array((np.r_[ell, ell], (np.r_[i, i + 1], np.r_[i + 1, i])), shape=(n, n))


def test_transport_drops_zero_weights_but_reports_caller_indices() -> None:
    """Zero-weight rows and columns are left out of the flow; the plan still indexes the
    caller's p and q, sorted by row then column."""
    cost = np.array([[9.0, 9.0, 9.0], [9.0, 2.0, 1.0], [9.0, 9.0, 9.0], [4.0, 9.0, 3.0]])
    problem = TransportProblem.build([0.0, 1.0, 0.0, 1.0], [1.0, 0.0, 1.0], cost, "equal")
    result = solve_transport_network(problem, time_limit_s=30.0, seed=0)
    assert result.status is Status.OPTIMAL and result.backend == "network"
    assert (result.stats["rows"], result.stats["cols"]) == (2.0, 2.0)
    assert result.plan is not None
    assert list(zip(result.plan.rows.tolist(), result.plan.cols.tolist(), strict=True)) == [
        (1, 2), (3, 0)]
    assert result.objective == pytest.approx((1.0 + 4.0) / 2.0)
    assert result.bound == result.objective and result.stats["pivots"] >= 1


@pytest.mark.parametrize(("p", "q", "cost", "expected", "cell"), [
    ([2.0, 1.0], [1.0], [[5.0], [1.0]], 1.0, (1, 0)),  # p heavier: a dummy column
    ([1.0], [1.0, 2.0], [[4.0, 2.0]], 2.0, (0, 1)),  # q heavier: a dummy row
])
def test_transport_partial_uses_a_dummy(p: list[float], q: list[float],
                                        cost: list[list[float]], expected: float,
                                        cell: tuple[int, int]) -> None:
    """Partial EMD moves min(Σp, Σq) = 1 by the cheapest cell; the dummy never shows in the plan."""
    problem = TransportProblem.build(p, q, cost, "partial")
    result = solve_transport_network(problem, time_limit_s=30.0, seed=0)
    assert result.objective == pytest.approx(expected) and result.plan is not None
    assert (result.plan.rows.tolist(), result.plan.cols.tolist()) == ([cell[0]], [cell[1]])
    assert result.plan.shape == problem.cost.shape and result.plan.total_flow == 1.0


@pytest.mark.parametrize(("p", "q", "expected"), [
    ([2.0, 0.0, 0.0], [0.0, 0.0, 1.0], 3.0),  # p heavier: one unit travels 1 + 2 m
    ([1.0, 0.0, 0.0], [0.0, 1.0, 3.0], 1.0),  # q heavier: the unit goes to the nearer node 1
])
def test_graph_partial_on_a_path(p: list[float], q: list[float], expected: float) -> None:
    """Partial EMD on a path 0 –1 m– 1 –2 m– 2; the plan holds graph arcs only."""
    problem = GraphProblem.build(_path([1.0, 2.0]), p, q, "partial")
    result = solve_graph_network(problem, time_limit_s=30.0, seed=0)
    assert result.status is Status.OPTIMAL and result.objective == pytest.approx(expected)
    assert result.plan is not None and result.plan.tails.max() < 3
    assert result.stats["nodes"] == 3.0 and result.stats["arcs"] == 4.0


def test_graph_flow_follows_arc_direction() -> None:
    """A one-way arc 1 → 0 cannot carry mass from 0 to 1 (INFEASIBLE, no plan), the other way
    costs its length."""
    one_way = sp.csr_array((np.array([4.0]), (np.array([1]), np.array([0]))), shape=(2, 2))
    back = solve_graph_network(GraphProblem.build(one_way, [0, 1], [1, 0], "normalize"),
                               time_limit_s=30.0, seed=0)
    assert back.status is Status.OPTIMAL and back.objective == pytest.approx(4.0)
    forth = solve_graph_network(GraphProblem.build(one_way, [1, 0], [0, 1], "normalize"),
                                time_limit_s=30.0, seed=0)
    assert forth.status is Status.INFEASIBLE and forth.plan is None
    assert "unrouted mass" in forth.message


def test_graph_without_arcs() -> None:
    """With no arcs, equal masses are 0 apart and different ones INFEASIBLE."""
    empty = sp.csr_array((2, 2))
    same = solve_graph_network(GraphProblem.build(empty, [1, 2], [1, 2], "normalize"),
                               time_limit_s=30.0, seed=0)
    assert same.status is Status.OPTIMAL and same.objective == 0.0
    apart = solve_graph_network(GraphProblem.build(empty, [1, 0], [0, 1], "normalize"),
                                time_limit_s=30.0, seed=0)
    assert apart.status is Status.INFEASIBLE
