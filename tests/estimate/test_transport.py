"""EMD (thesis §4.3): brute force on tiny cases, network simplex vs LP, graph flow vs matrix."""

from __future__ import annotations

import itertools
import math
from typing import Any

import networkx as nx
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse import csgraph

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Sense, Status
from searchtrack.estimate.transport import (
    EMD_BACKENDS,
    GRAPH_EMD_BACKENDS,
    TransportPlan,
    TransportProblem,
    emd,
    emd_on_graph,
)
from searchtrack.estimate.transport.lp import map_status as lp_status
from searchtrack.estimate.transport.lp import solve_transport_lp
from searchtrack.estimate.transport.network import map_status as network_status
from searchtrack.estimate.transport.simplex import FlowSolution
from searchtrack.estimate.transport.solve import _auto, transport_violations
from searchtrack.models.roads import RoadNetwork

RTOL = 1e-9
BACKENDS = ["network", "lp"]


def _vertex_minimum(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> float:
    """min c·x over {a x = b, x ≥ 0} by enumerating every basic feasible solution."""
    rank = np.linalg.matrix_rank(a)
    best = math.inf
    for cols in itertools.combinations(range(a.shape[1]), rank):
        sub = a[:, cols]
        if np.linalg.matrix_rank(sub) < rank:
            continue
        x = np.linalg.lstsq(sub, b, rcond=None)[0]
        if np.allclose(sub @ x, b, atol=1e-12) and (x >= -1e-12).all():
            best = min(best, float(c[list(cols)] @ x))
    return best


def _brute_emd(p: np.ndarray, q: np.ndarray, cost: np.ndarray, partial: bool) -> float:
    """EMD from the vertices of the transport polytope (4.4)–(4.7), slacks for partial."""
    m, n = cost.shape
    rows = np.kron(np.eye(m), np.ones((1, n)))
    cols = np.kron(np.ones((1, m)), np.eye(n))
    if not partial:
        p, q = p / p.sum(), q / q.sum()
        return _vertex_minimum(np.vstack([rows, cols]), np.r_[p, q], cost.ravel())
    total = float(min(p.sum(), q.sum()))
    a = np.block([[rows, np.eye(m), np.zeros((m, n))],
                  [cols, np.zeros((n, m)), np.eye(n)],
                  [np.ones((1, m * n)), np.zeros((1, m + n))]])
    c = np.r_[cost.ravel(), np.zeros(m + n)]
    return _vertex_minimum(a, np.r_[p, q, total], c) / total


def _grid(side: int, rng: np.random.Generator, directed: bool = False) -> sp.csr_array:
    """A road-like grid with edge lengths 5–15 m (both directions stored)."""
    graph = nx.grid_2d_graph(side, side)
    adj = sp.coo_array(nx.to_scipy_sparse_array(graph, format="coo", dtype=float))
    upper = adj.row < adj.col
    i, j = adj.row[upper], adj.col[upper]
    ell = rng.uniform(5.0, 15.0, i.size)
    back = rng.uniform(5.0, 15.0, i.size) if directed else ell
    n = side * side
    return sp.csr_array((np.r_[ell, back], (np.r_[i, j], np.r_[j, i])), shape=(n, n))


TINY = [
    (np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.array([[0.0, 1.0], [1.0, 0.0]]), 0.0),
    (np.array([0.5, 0.5]), np.array([0.5, 0.5]), np.array([[1.0, 0.0], [0.0, 1.0]]), 0.0),
    (np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([[0.0, 3.0], [3.0, 0.0]]), 3.0),
    (np.array([0.3, 0.7]), np.array([0.2, 0.5, 0.3]), np.array([[1.0, 2.0, 3.0],
                                                               [4.0, 1.0, 2.0]]), None),
    (np.array([2.0, 1.0, 1.0]), np.array([1.0, 3.0]), np.array([[1.0, 1.0], [0.0, 5.0],
                                                               [2.0, 2.0]]), None),
]


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("case", range(len(TINY)))
def test_tiny_cases_match_vertex_enumeration(case: int, backend: str) -> None:
    """On 2×2, 2×3 and 3×2 instances both backends find the best vertex of the polytope."""
    p, q, cost, known = TINY[case]
    result = emd(p, q, cost, backend=backend)
    assert result.status is Status.OPTIMAL and result.sense is Sense.MINIMIZE
    expected = _brute_emd(p, q, cost, partial=False)
    if known is not None:
        assert expected == pytest.approx(known)
    assert result.objective == pytest.approx(expected, rel=RTOL, abs=1e-12)


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("seed", range(4))
def test_random_tiny_cases_match_vertex_enumeration(seed: int, backend: str) -> None:
    """Random 2×3 / 3×2 instances, normalised and partial, match the enumerated optimum."""
    rng = np.random.default_rng(seed)
    m, n = (2, 3) if seed % 2 else (3, 2)
    p, q = rng.integers(0, 4, m) + 0.5, rng.integers(0, 4, n) + 0.5
    cost = rng.integers(0, 5, (m, n)).astype(float)
    for mass in ("normalize", "partial"):
        result = emd(p, q, cost, mass=mass, backend=backend)
        expected = _brute_emd(p, q, cost, partial=mass == "partial")
        assert result.objective == pytest.approx(expected, rel=RTOL, abs=1e-12), mass


def test_graph_emd_on_a_path_is_the_cdf_distance() -> None:
    """On a path graph the EMD is Σ ℓ |CDF_p − CDF_q| (closed form), for both graph backends."""
    rng = np.random.default_rng(7)
    n = 40
    lengths = rng.uniform(5.0, 15.0, n - 1)
    i = np.arange(n - 1)
    adj = sp.csr_array((np.r_[lengths, lengths], (np.r_[i, i + 1], np.r_[i + 1, i])),
                       shape=(n, n))
    p, q = rng.random(n), rng.random(n)
    expected = float(lengths @ np.abs(np.cumsum(p / p.sum() - q / q.sum())[:-1]))
    for backend in BACKENDS:
        assert emd_on_graph(adj, p, q, backend=backend).objective == pytest.approx(expected,
                                                                                  rel=RTOL)
    # the same path as a RoadNetwork: its edge lengths are the metric
    coords = np.column_stack([np.r_[0.0, np.cumsum(lengths)], np.zeros(n)])
    net = RoadNetwork(coords, np.column_stack([i, i + 1]), lengths)
    assert emd_on_graph(net, p, q).objective == pytest.approx(expected, rel=RTOL)


@pytest.mark.parametrize("mass", ["normalize", "partial", "equal"])
def test_network_agrees_with_lp(mass: str) -> None:
    """Network simplex and the cvxpy/HiGHS LP agree to 1e-9 on 30×40 with zero weights."""
    rng = np.random.default_rng(11)
    p = rng.random(30) * (rng.random(30) < 0.7)
    q = rng.random(40) * (rng.random(40) < 0.7)
    q *= (2.5 if mass == "partial" else 1.0) * p.sum() / q.sum()
    cost = rng.uniform(0.0, 100.0, (30, 40))
    fast, ref = (emd(p, q, cost, mass=mass, backend=b) for b in BACKENDS)
    assert fast.status is ref.status is Status.OPTIMAL
    assert fast.objective == pytest.approx(ref.objective, rel=RTOL)
    assert fast.plan is not None and fast.plan.rows.size <= 30 + 40 - 1


def test_degenerate_random_instances_agree_with_lp() -> None:
    """Integer masses and costs in 0..3 (many ties, degenerate pivots) match the LP."""
    rng = np.random.default_rng(17)
    for _ in range(12):
        m, n = rng.integers(1, 9, 2)
        p = rng.integers(0, 3, m).astype(float)
        q = rng.integers(0, 3, n).astype(float)
        p[0], q[-1] = p[0] + 1.0, q[-1] + 1.0
        cost = rng.integers(0, 4, (m, n)).astype(float)
        fast, ref = (emd(p, q, cost, mass="partial", backend=b) for b in BACKENDS)
        assert fast.objective == pytest.approx(ref.objective, rel=RTOL, abs=1e-12)


def test_degenerate_grid_with_uniform_masses() -> None:
    """Uniform masses on a 10 m lattice (highly degenerate) still agree with the LP."""
    graph = nx.grid_2d_graph(8, 8)
    adj = sp.csr_array(nx.to_scipy_sparse_array(graph, format="csr", dtype=float) * 10.0)
    dist = csgraph.dijkstra(adj, directed=False)
    p = np.zeros(64)
    q = np.zeros(64)
    p[:32], q[16:48] = 1.0, 1.0
    values = [emd(p, q, dist, backend=b).objective for b in BACKENDS]
    values += [emd_on_graph(adj, p, q, backend=b).objective for b in BACKENDS]
    assert all(v == pytest.approx(values[1], rel=RTOL) for v in values), values


@pytest.mark.parametrize("directed", [False, True])
@pytest.mark.parametrize("mass", ["normalize", "partial"])
def test_graph_flow_agrees_with_dijkstra_matrix(mass: str, directed: bool) -> None:
    """emd_on_graph (both backends) equals emd with the full Dijkstra distance matrix."""
    rng = np.random.default_rng(5)
    adj = _grid(9, rng, directed=directed)
    n = adj.shape[0]
    p = rng.random(n) * (rng.random(n) < 0.5)
    q = rng.random(n) * (rng.random(n) < 0.5) * (3.0 if mass == "partial" else 1.0)
    dist = csgraph.dijkstra(adj, directed=True)
    matrix = emd(p, q, dist, mass=mass, backend="network")
    for backend in BACKENDS:
        graph = emd_on_graph(adj, p, q, mass=mass, backend=backend)
        assert graph.status is Status.OPTIMAL, graph.message
        assert graph.objective == pytest.approx(matrix.objective, rel=RTOL), backend


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


def test_masses_normalise_partial_and_equal() -> None:
    """Normalised EMD ignores scale; partial EMD moves min(Σp, Σq); 'equal' keeps units."""
    p, q = np.array([1.0, 1.0]), np.array([0.0, 1.0])
    cost = np.array([[0.0, 2.0], [2.0, 0.0]])
    assert emd(3 * p, q, cost).objective == pytest.approx(1.0)
    partial = emd(p, q, cost, mass="partial")
    assert partial.objective == pytest.approx(0.0)
    assert partial.plan is not None and partial.plan.total_flow == pytest.approx(1.0)
    equal = emd(p, 2 * q, cost, mass="equal")
    assert equal.objective == pytest.approx(1.0)
    assert equal.plan is not None and equal.plan.work == pytest.approx(2.0)


def test_identical_and_nearly_identical_signatures() -> None:
    """p = q gives 0; p within 1e-12 of q gives a tiny EMD, not a round-off INFEASIBLE."""
    rng = np.random.default_rng(4)
    adj = _grid(6, rng)
    p = rng.random(36)
    q = p * (1.0 + 1e-12 * rng.standard_normal(36))
    dist = csgraph.dijkstra(adj, directed=True)
    for backend in BACKENDS:
        assert emd_on_graph(adj, p, p, backend=backend).objective == pytest.approx(0.0, abs=1e-15)
        assert emd(p, p, dist, backend=backend).objective == pytest.approx(0.0, abs=1e-15)
        near = emd_on_graph(adj, p, q, backend=backend)
        assert near.status is Status.OPTIMAL and near.objective == pytest.approx(0.0, abs=1e-9)


def test_disconnected_graph_is_infeasible() -> None:
    """Mass that must cross between components is INFEASIBLE; within one it is fine."""
    adj = sp.csr_array((np.ones(4), ([0, 1, 2, 3], [1, 0, 3, 2])), shape=(4, 4))
    for backend in BACKENDS:
        bad = emd_on_graph(adj, [1, 0, 0, 0], [0, 0, 1, 0], backend=backend)
        assert bad.status is Status.INFEASIBLE and bad.plan is None, backend
        good = emd_on_graph(adj, [1, 0, 1, 0], [0, 1, 0, 1], backend=backend)
        assert good.objective == pytest.approx(1.0), backend


def test_time_limit_gives_no_solution_not_a_wrong_one() -> None:
    """A time limit too short for any pivot returns NO_SOLUTION without a plan."""
    rng = np.random.default_rng(0)
    result = emd(rng.random(200), rng.random(200), rng.random((200, 200)), backend="network",
                 time_limit_s=1e-9)
    assert result.status is Status.NO_SOLUTION and result.plan is None


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


def test_status_mapping_is_explicit() -> None:
    """Each native status maps to one of ours; anything unknown is ERROR."""
    assert lp_status("optimal") is Status.OPTIMAL
    assert lp_status("infeasible") is Status.INFEASIBLE
    assert lp_status("optimal_inaccurate") is Status.NO_SOLUTION
    assert lp_status("unbounded") is Status.ERROR
    assert lp_status("something new") is Status.ERROR
    empty = (np.zeros(0, dtype=np.int64), np.zeros(0))

    def raw(status: Any, unrouted: float) -> FlowSolution:
        return FlowSolution(status, *empty, unrouted, 0, routed=unrouted == 0.0)

    assert network_status(raw("optimal", 0.0)) is Status.OPTIMAL
    assert network_status(raw("infeasible", 1.0)) is Status.INFEASIBLE
    assert network_status(raw("time_limit", 0.0)) is Status.FEASIBLE
    assert network_status(raw("time_limit", 0.5)) is Status.NO_SOLUTION
    assert network_status(raw("unbounded", 0.0)) is Status.ERROR
    assert network_status(raw("weird", 0.0)) is Status.ERROR


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
