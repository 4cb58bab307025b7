"""EMD instances with known optima (vertex enumeration, closed forms, the other backend) run
against every backend, on cost matrices and on graphs (thesis §4.3)."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse import csgraph

from searchtrack.core.result import Sense, Status
from searchtrack.estimate.transport import emd, emd_on_graph
from searchtrack.models.roads import RoadNetwork

from .helpers import BACKENDS, RTOL, TINY
from .helpers import brute_emd as _brute_emd
from .helpers import grid as _grid


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
