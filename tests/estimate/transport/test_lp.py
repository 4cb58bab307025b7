"""The cvxpy/HiGHS reference backend: the transportation LP and the graph min-cost flow LP."""

from __future__ import annotations

import cvxpy.settings as cps
import numpy as np
import pytest
import scipy.sparse as sp

from searchtrack.core.result import Sense, Status
from searchtrack.estimate.transport import GraphProblem, TransportProblem
from searchtrack.estimate.transport.lp import map_status, solve_graph_lp, solve_transport_lp
from searchtrack.estimate.transport.network import solve_graph_network


def _path(lengths: list[float]) -> sp.csr_array:
    """An undirected path whose consecutive nodes are ``lengths`` apart."""
    n = len(lengths) + 1
    i = np.arange(n - 1)
    ell = np.asarray(lengths, dtype=float)
    return sp.csr_array((np.r_[ell, ell], (np.r_[i, i + 1], np.r_[i + 1, i])), shape=(n, n))


def test_transport_lp_moves_a_point_mass() -> None:
    """All of p[0] must go to q[1] at cost 3: EMD 3, one plan entry, bound = objective."""
    problem = TransportProblem.build([1.0, 0.0], [0.0, 1.0], [[0.0, 3.0], [3.0, 0.0]],
                                     "normalize")
    result = solve_transport_lp(problem, time_limit_s=30.0, seed=0)
    assert result.status is Status.OPTIMAL and result.backend == "lp"
    assert result.sense is Sense.MINIMIZE and result.stats["variables"] == 4.0
    assert result.objective == pytest.approx(3.0) and result.bound == result.objective
    assert result.plan is not None
    assert (result.plan.rows.tolist(), result.plan.cols.tolist()) == ([0], [1])
    assert result.plan.amounts == pytest.approx([1.0])


def test_transport_lp_partial_by_hand() -> None:
    """p = (2, 1), q = (1,), costs (5, 1): partial EMD sends q's unit from the cheap row (1)."""
    problem = TransportProblem.build([2.0, 1.0], [1.0], [[5.0], [1.0]], "partial")
    result = solve_transport_lp(problem, time_limit_s=30.0, seed=0)
    assert result.objective == pytest.approx(1.0) and result.plan is not None
    assert result.plan.total_flow == 1.0
    np.testing.assert_allclose(result.plan.dense(), [[0.0], [1.0]], atol=1e-12)


@pytest.mark.parametrize(("p", "q", "expected"), [
    ([2.0, 0.0, 0.0], [0.0, 0.0, 1.0], 3.0),  # p heavier: one unit travels 1 + 2 m
    ([1.0, 0.0, 0.0], [0.0, 1.0, 3.0], 1.0),  # q heavier: the unit goes to the nearer node 1
])
def test_graph_lp_partial_on_a_path(p: list[float], q: list[float], expected: float) -> None:
    """Partial EMD on a path 0 –1 m– 1 –2 m– 2: the heavier side chooses what to use."""
    problem = GraphProblem.build(_path([1.0, 2.0]), p, q, "partial")
    result = solve_graph_lp(problem, time_limit_s=30.0, seed=0)
    assert result.status is Status.OPTIMAL and result.objective == pytest.approx(expected)
    assert result.stats["variables"] == 4.0


def test_graph_lp_without_arcs() -> None:
    """With no arcs, equal masses are 0 apart; different masses cannot be moved (INFEASIBLE),
    as the network backend answers."""
    empty = sp.csr_array((2, 2))
    same = solve_graph_lp(GraphProblem.build(empty, [1, 2], [1, 2], "normalize"),
                          time_limit_s=30.0, seed=0)
    assert same.status is Status.OPTIMAL and same.objective == 0.0
    assert same.plan is not None and same.plan.tails.size == 0
    apart = solve_graph_lp(GraphProblem.build(empty, [1, 0], [0, 1], "normalize"),
                           time_limit_s=30.0, seed=0)
    assert apart.status is Status.INFEASIBLE and apart.plan is None and apart.objective is None


@pytest.mark.parametrize(("p", "q", "mass", "status", "objective"), [
    ([1.0], [1.0], "normalize", Status.OPTIMAL, 0.0),  # one node, no arc
    ([2.0, 1.0], [1.0, 0.0], "partial", Status.OPTIMAL, 0.0),  # q's unit is met in place
    ([1.0, 0.0], [2.0, 1.0], "partial", Status.OPTIMAL, 0.0),  # p's unit is met in place
    ([1.0, 0.0], [0.0, 1.0], "partial", Status.INFEASIBLE, None),  # nothing can move
])
def test_graph_lp_without_arcs_answers_like_the_network(
    p: list[float], q: list[float], mass: str, status: Status, objective: float | None,
) -> None:
    """On graphs without arcs the LP gives the network simplex's status and objective."""
    problem = GraphProblem.build(sp.csr_array((len(p), len(p))), p, q, mass)
    lp = solve_graph_lp(problem, time_limit_s=30.0, seed=0)
    network = solve_graph_network(problem, time_limit_s=30.0, seed=0)
    assert (lp.status, lp.objective) == (network.status, network.objective) == (status, objective)


@pytest.mark.parametrize(("native", "ours"), [
    (cps.OPTIMAL, Status.OPTIMAL),
    (cps.OPTIMAL_INACCURATE, Status.NO_SOLUTION),
    (cps.INFEASIBLE, Status.INFEASIBLE),
    (cps.INFEASIBLE_INACCURATE, Status.INFEASIBLE),
    (cps.USER_LIMIT, Status.NO_SOLUTION),
    (cps.UNBOUNDED, Status.ERROR),
    (cps.UNBOUNDED_INACCURATE, Status.ERROR),
    (cps.INFEASIBLE_OR_UNBOUNDED, Status.ERROR),
    (cps.SOLVER_ERROR, Status.ERROR),
])
def test_every_cvxpy_status_is_mapped(native: str, ours: Status) -> None:
    """Each cvxpy status has its own explicit mapping."""
    assert map_status(native) is ours
