"""EMD by backend name: checked plans, untouched inputs, bad input naming the field, the auto
fallback."""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse import csgraph

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Status
from searchtrack.estimate.transport import (
    EMD_BACKENDS,
    GRAPH_EMD_BACKENDS,
    GraphFlow,
    GraphProblem,
    TransportPlan,
    TransportProblem,
    emd,
    emd_on_graph,
)
from searchtrack.estimate.transport.lp import solve_transport_lp
from searchtrack.estimate.transport.solve import _auto, graph_violations, transport_violations

from .helpers import TINY
from .helpers import grid as _grid


def test_plans_are_feasible_and_inputs_untouched() -> None:
    """Plans meet the marginals (indices of the caller's arrays); inputs are not modified."""
    rng = np.random.default_rng(2)
    adj = _grid(5, rng)
    p, q = rng.random(25), rng.random(25)
    p[[0, 3]] = 0.0
    dist = csgraph.dijkstra(adj, directed=True)
    before = [a.copy() for a in (p, q, dist)]
    result = emd(p, q, dist)
    assert result.plan is not None
    flow = result.plan.dense()
    np.testing.assert_allclose(flow.sum(axis=1), p / p.sum(), atol=1e-14)
    np.testing.assert_allclose(flow.sum(axis=0), q / q.sum(), atol=1e-14)
    assert result.plan.work == pytest.approx(float((flow * dist).sum()))
    on_graph = emd_on_graph(adj, p, q)
    assert on_graph.plan is not None
    np.testing.assert_allclose(on_graph.plan.net_outflow(), p / p.sum() - q / q.sum(),
                               atol=1e-14)
    for old, new in zip(before, (p, q, dist), strict=True):
        np.testing.assert_array_equal(old, new)


_P, _Q, _C = np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.ones((2, 2))
_ADJ = sp.csr_array(np.array([[0.0, 1.0], [1.0, 0.0]]))
BAD: list[tuple[str, dict[str, Any]]] = [
    ("p", {"p": [-0.1, 1.1]}),
    ("p", {"p": [math.nan, 1.0]}),
    ("p", {"p": [[0.5, 0.5]]}),
    ("p", {"p": [0.0, 0.0]}),
    ("q", {"q": [0.5, math.inf]}),
    ("cost", {"cost": np.ones((2, 3))}),
    ("cost", {"cost": np.array([[0.0, -1.0], [1.0, 0.0]])}),
    ("cost", {"cost": np.array([[0.0, math.nan], [1.0, 0.0]])}),
    ("q", {"q": [0.5, 0.6], "mass": "equal"}),
    ("mass", {"mass": "scaled"}),
    ("backend", {"backend": "simplex"}),
    ("time_limit_s", {"time_limit_s": 0.0}),
]


@pytest.mark.parametrize(("field", "change"), BAD)
def test_bad_inputs_name_the_field(field: str, change: dict[str, Any]) -> None:
    """Bad weights, costs, shapes, masses and options raise InvalidInputError naming the field."""
    args: dict[str, Any] = {"p": _P, "q": _Q, "cost": _C, **change}
    with pytest.raises(InvalidInputError) as err:
        emd(**args)
    assert err.value.field == field


GRAPH_BAD: list[tuple[str, dict[str, Any]]] = [
    ("adjacency", {"adjacency": np.array([[0.0, 1.0], [1.0, 0.0]])}),
    ("adjacency", {"adjacency": sp.csr_array(np.ones((2, 3)))}),
    ("adjacency", {"adjacency": sp.csr_array(np.array([[0.0, -1.0], [1.0, 0.0]]))}),
    ("adjacency", {"adjacency": sp.csr_array(np.array([[0.0, math.nan], [1.0, 0.0]]))}),
    ("p", {"p": [1.0, 0.0, 0.0]}),
    ("q", {"q": [-1.0, 2.0]}),
]


@pytest.mark.parametrize(("field", "change"), GRAPH_BAD)
def test_bad_graph_inputs_name_the_field(field: str, change: dict[str, Any]) -> None:
    """Dense, non-square, negative or NaN adjacency and wrong-length weights name the field."""
    args: dict[str, Any] = {"adjacency": _ADJ, "p": _P, "q": _Q, **change}
    with pytest.raises(InvalidInputError) as err:
        emd_on_graph(**args)
    assert err.value.field == field


def test_auto_falls_back_to_the_lp() -> None:
    """When the network simplex fails, auto answers with the LP and says why."""

    def broken(problem: TransportProblem, /, *, time_limit_s: float,
               seed: int) -> Result[TransportPlan]:
        return Result(Status.ERROR, None, None, 0.0, "network", None, message="boom")

    solve = _auto(broken, solve_transport_lp, transport_violations)
    problem = TransportProblem.build(TINY[3][0], TINY[3][1], TINY[3][2], "normalize")
    result = solve(problem, time_limit_s=30.0, seed=0)
    assert result.status is Status.OPTIMAL and result.backend == "lp"
    assert "boom" in result.message
    assert EMD_BACKENDS.names() == GRAPH_EMD_BACKENDS.names() == ["auto", "network", "lp"]


def _transport(rows: list[int], cols: list[int], amounts: list[float],
               problem: TransportProblem) -> TransportPlan:
    """A hand-written plan for ``problem`` (work left at 0: only the marginals are judged)."""
    return TransportPlan(np.array(rows), np.array(cols), np.array(amounts),
                         problem.cost.shape, 0.0, problem.total_flow)


def test_transport_violations_name_the_broken_constraint() -> None:
    """A valid plan has none; wrong row or column sums and negative flow are each named with
    the thesis equation they break."""
    problem = TransportProblem.build([0.5, 0.5], [1.0], [[1.0], [2.0]], "normalize")
    assert transport_violations(problem, _transport([0, 1], [0, 0], [0.5, 0.5], problem)) == []
    short = transport_violations(problem, _transport([0, 1], [0, 0], [0.5, 0.4], problem))
    assert short == ["flow out of p (4.5) off by 0.1", "flow into q (4.6) off by 0.1"]
    negative = transport_violations(problem, _transport([0, 1, 1], [0, 0, 0], [0.5, 0.6, -0.1],
                                                        problem))
    assert negative == ["negative flow (4.4)"]


def test_partial_transport_violations_check_bounds_and_total() -> None:
    """Partial plans may leave mass behind but not exceed p or q, and must move min(Σp, Σq)."""
    problem = TransportProblem.build([2.0, 1.0], [1.0], [[1.0], [2.0]], "partial")
    assert transport_violations(problem, _transport([0], [0], [1.0], problem)) == []
    too_little = transport_violations(problem, _transport([0], [0], [0.5], problem))
    assert len(too_little) == 1
    assert too_little[0].startswith("total flow") and "0.5" in too_little[0]
    assert too_little[0].endswith("!= 1.0 (4.7)")
    over = transport_violations(problem, _transport([1], [0], [1.5], problem))
    assert "flow out of p (4.5) outside its bounds by 0.5" in over
    assert "flow into q (4.6) outside its bounds by 0.5" in over


def test_total_flow_violation_prints_plain_numbers() -> None:
    """A partial plan that moves 0.5 of 1 is reported with plain numbers, not NumPy reprs."""
    problem = TransportProblem.build([2.0, 1.0], [1.0], [[1.0], [2.0]], "partial")
    problem = dataclasses.replace(problem, total_flow=np.float64(1.0))
    short = transport_violations(problem, _transport([0], [0], [0.5], problem))
    assert short == ["total flow 0.5 != 1.0 (4.7)"]


def test_graph_violations_check_conservation() -> None:
    """A flow must send p − q out of each node; for partial EMD only within the bounds."""
    adj = sp.csr_array(np.array([[0.0, 1.0], [1.0, 0.0]]))
    problem = GraphProblem.build(adj, [1.0, 0.0], [0.0, 1.0], "normalize")

    def flow(amount: float) -> GraphFlow:
        return GraphFlow(np.array([0]), np.array([1]), np.array([amount]), 2, amount, 1.0)

    assert graph_violations(problem, flow(1.0)) == []
    assert graph_violations(problem, flow(0.75)) == ["flow conservation B f = p − q off by 0.25"]
    assert graph_violations(problem, flow(-1.0))[0] == "negative flow"
    partial = GraphProblem.build(adj, [3.0, 0.0], [0.0, 1.0], "partial")
    assert graph_violations(partial, flow(1.0)) == []
    assert graph_violations(partial, flow(2.0)) == ["net outflow outside its bounds by 1"]


def test_auto_rejects_a_wrong_plan_and_falls_back() -> None:
    """A network answer whose plan breaks the marginals counts as ERROR; auto then answers with
    the LP and names the failed check."""

    def wrong(problem: TransportProblem, /, *, time_limit_s: float,
              seed: int) -> Result[TransportPlan]:
        plan = _transport([0], [0], [0.25], problem)
        return Result(Status.OPTIMAL, 0.0, 0.0, 0.0, "network", plan)

    solve = _auto(wrong, solve_transport_lp, transport_violations)
    problem = TransportProblem.build([1.0, 1.0], [2.0], [[1.0], [3.0]], "normalize")
    result = solve(problem, time_limit_s=30.0, seed=0)
    assert result.backend == "lp" and result.objective == pytest.approx(2.0)
    assert "plan check failed: flow out of p (4.5) off by" in result.message


def test_default_backend_is_the_network_simplex() -> None:
    """emd and emd_on_graph answer through auto with the network simplex when it succeeds."""
    result = emd([1.0, 0.0], [0.0, 1.0], [[0.0, 3.0], [3.0, 0.0]])
    assert result.backend == "network" and result.objective == pytest.approx(3.0)
    assert result.message.endswith("network answered")
    on_graph = emd_on_graph(_ADJ, [1.0, 0.0], [0.0, 1.0])
    assert on_graph.backend == "network" and on_graph.objective == pytest.approx(1.0)
