"""The trackers × measurements EMD matrix: exact values, gate pruning, unsolved pairs, bad input."""

from __future__ import annotations

import logging
import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Sense, Status
from searchtrack.estimate.emd_matrix import (
    EMD_MATRIX_BACKENDS,
    EMDMatrixProblem,
    emd_matrix,
    solve_emd_matrix,
)
from searchtrack.estimate.signatures import (
    truncate_signature,
)
from searchtrack.estimate.transport import emd, emd_on_graph
from searchtrack.models import RoadNetwork, random_network
from searchtrack.models.road_metric import RoadMetric


def line_network(lengths: list[float]) -> RoadNetwork:
    """A straight road whose consecutive nodes are ``lengths`` apart."""
    x = np.concatenate([[0.0], np.cumsum(lengths)])
    n = x.size
    edges = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return RoadNetwork(np.column_stack([x, np.zeros(n)]), edges, np.array(lengths))


def _rows(rng: np.random.Generator, r: int, n: int, density: float = 1.0) -> np.ndarray:
    w = rng.random((r, n)) * (rng.random((r, n)) < density)
    w[:, 0] += 1e-3  # never an empty row
    return w / w.sum(axis=1, keepdims=True)


# ----- exact values --------------------------------------------------------------------------

@pytest.mark.parametrize("method", ["transport", "graph"])
def test_line_matches_the_cdf_formula(method: str) -> None:
    """On a line with uneven spacing, W1 = Σ_edges |CDF_p − CDF_q| × length."""
    rng = np.random.default_rng(7)
    lengths = rng.uniform(5.0, 20.0, size=11).tolist()
    net = line_network(lengths)
    p, q = _rows(rng, 3, net.n_nodes, 0.6), _rows(rng, 2, net.n_nodes, 0.6)
    got = emd_matrix(net, p, q, support_mass=1.0, backend=method)
    cdf_gap = np.abs(np.cumsum(p, axis=1)[:, None, :-1] - np.cumsum(q, axis=1)[None, :, :-1])
    np.testing.assert_allclose(got, cdf_gap @ np.array(lengths), rtol=1e-9)


@pytest.mark.parametrize("method", ["transport", "graph"])
def test_random_network_matches_emd_on_graph(method: str) -> None:
    """Without truncation, every entry equals emd_on_graph on the whole network."""
    net = random_network(8, 300.0, seed=4)
    rng = np.random.default_rng(4)
    p, q = _rows(rng, 3, net.n_nodes, 0.3), _rows(rng, 2, net.n_nodes, 0.3)
    got = emd_matrix(net, p, q, support_mass=1.0, backend=method)
    want = [[emd_on_graph(net.adjacency, pi, qj, backend="lp").objective for qj in q] for pi in p]
    np.testing.assert_allclose(got, np.array(want, dtype=float), rtol=1e-7)


def test_truncated_matrix_is_the_emd_of_the_truncated_signatures() -> None:
    """Both methods give the EMD between truncated signatures, under Dijkstra distances."""
    net = random_network(8, 300.0, seed=5)
    metric = RoadMetric(net)
    rng = np.random.default_rng(5)
    p, q = _rows(rng, 2, net.n_nodes), _rows(rng, 2, net.n_nodes)
    got = emd_matrix(metric, p, q, support_mass=0.9)
    np.testing.assert_allclose(emd_matrix(metric, p, q, support_mass=0.9, backend="graph"), got,
                               rtol=1e-7)
    for i, j in np.ndindex(2, 2):
        a, b = truncate_signature(p[i], 0.9), truncate_signature(q[j], 0.9)
        cost = net.shortest_paths(a.nodes)[:, b.nodes]
        assert got[i, j] == pytest.approx(emd(a.weights, b.weights, cost).objective, rel=1e-9)


def test_either_side_can_be_the_distance_source() -> None:
    """EMD is symmetric, whichever side (the one with fewer support nodes) runs Dijkstra."""
    net = random_network(8, 300.0, seed=9)
    metric = RoadMetric(net)
    rng = np.random.default_rng(9)
    narrow, wide = _rows(rng, 2, net.n_nodes, 0.05), _rows(rng, 3, net.n_nodes, 0.6)
    forward = emd_matrix(metric, narrow, wide)  # the trackers' side is the smaller
    np.testing.assert_allclose(emd_matrix(metric, wide, narrow).T, forward, rtol=1e-9)
    brute = [[emd(a, b, net.shortest_paths(np.arange(net.n_nodes))).objective for b in wide]
             for a in narrow]
    np.testing.assert_allclose(emd_matrix(metric, narrow, wide, support_mass=1.0),
                               np.array(brute, dtype=float), rtol=1e-9)


def test_gate_only_skips_pairs_at_or_above_it() -> None:
    """With a gate, entries below it are unchanged and the rest are inf or ≥ the gate."""
    net = random_network(10, 600.0, seed=6)
    metric = RoadMetric(net)
    rng = np.random.default_rng(6)
    p, q = _rows(rng, 4, net.n_nodes, 0.05), _rows(rng, 3, net.n_nodes, 0.05)
    full = emd_matrix(metric, p, q)
    gate = float(np.median(full))
    gated = emd_matrix(metric, p, q, gate_m=gate)
    below = full < gate
    assert below.any() and (~below).any()
    np.testing.assert_array_equal(gated[below], full[below])
    assert ((gated[~below] == full[~below]) | np.isinf(gated[~below])).all()


def test_disconnected_supports() -> None:
    """Mass that must cross components gives inf; matching masses per component add up."""
    coords = np.array([[0.0, 0.0], [10.0, 0.0], [20.0, 0.0], [0.0, 50.0], [10.0, 50.0]])
    net = RoadNetwork(coords, np.array([[0, 1], [1, 2], [3, 4]]), np.array([10.0, 10.0, 10.0]))
    p = np.array([[0.5, 0.0, 0.0, 0.5, 0.0], [1.0, 0.0, 0.0, 0.0, 0.0]])
    q = np.array([[0.0, 0.0, 0.5, 0.0, 0.5]])
    for method in ("transport", "graph"):
        got = emd_matrix(net, p, q, support_mass=1.0, backend=method)
        assert got[0, 0] == pytest.approx(0.5 * 20.0 + 0.5 * 10.0)
        assert math.isinf(got[1, 0])


def test_empty_sides_and_expired_time_limit() -> None:
    """No trackers or no measurements give an empty matrix; no time left leaves inf (logged)."""
    net = line_network([10.0] * 4)
    one = np.eye(5)[[2]]
    assert emd_matrix(net, np.zeros((0, 5)), one).shape == (0, 1)
    assert emd_matrix(net, one, np.zeros((0, 5))).shape == (1, 0)
    assert emd_matrix(net, one, np.eye(5)[[0]])[0, 0] == pytest.approx(20.0)
    assert math.isinf(emd_matrix(net, one, np.eye(5)[[0]], time_limit_s=1e-9)[0, 0])


@pytest.mark.parametrize("backend", EMD_MATRIX_BACKENDS.names())
def test_catalogue_every_backend_proves_a_known_matrix(backend: str) -> None:
    """Each backend returns the known EMDs on a line as an OPTIMAL minimisation, nothing
    unsolved; the gate proves the far pair without solving it."""
    net = line_network([10.0] * 4)
    problem = EMDMatrixProblem.build(net, np.eye(5)[[0, 4]], np.eye(5)[[1, 2]], support_mass=1.0,
                                     gate_m=25.0)
    result = solve_emd_matrix(problem, backend=backend)
    assert result.status is Status.OPTIMAL and result.sense is Sense.MINIMIZE
    assert result.plan is not None and not result.plan.unsolved.any()
    np.testing.assert_allclose(result.plan.costs, [[10.0, 20.0], [math.inf, 20.0]])
    assert result.objective == pytest.approx(50.0)


def test_unsolved_pairs_are_reported_not_hidden(caplog: pytest.LogCaptureFixture) -> None:
    """A matrix cut off by its time limit is FEASIBLE, marks the pairs it left at +inf, and
    says the time limit (not the solver) left them."""
    net = line_network([10.0] * 4)
    problem = EMDMatrixProblem.build(net, np.eye(5)[[2]], np.eye(5)[[0]])
    with caplog.at_level(logging.WARNING, logger="searchtrack.estimate.emd_matrix"):
        result = solve_emd_matrix(problem, time_limit_s=1e-9)
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert result.plan.unsolved.tolist() == [[True]] and "unsolved" in result.message
    assert [r.getMessage() for r in caplog.records] == [
        "emd_matrix: 1 of 1 pairs left unsolved at +inf: time limit 1e-09 s reached"]


@pytest.mark.parametrize(("change", "field"), [
    ({"bank_probabilities": np.ones((2, 4))}, "bank_probabilities"),
    ({"bank_probabilities": np.ones(5)}, "bank_probabilities"),
    ({"bank_probabilities": -np.ones((1, 5))}, "bank_probabilities"),
    ({"bank_probabilities": np.zeros((1, 5))}, "bank_probabilities"),
    ({"densities": np.full((1, 5), np.inf)}, "densities"),
    ({"densities": [["a"] * 5]}, "densities"),
    ({"support_mass": 0.0}, "support_mass"),
    ({"gate_m": 0.0}, "gate_m"),
    ({"gate_m": math.nan}, "gate_m"),
    ({"backend": "simplex"}, "backend"),
    ({"time_limit_s": 0.0}, "time_limit_s"),
    ({"network": "roads"}, "network"),
])
def test_bad_input(change: dict[str, object], field: str) -> None:
    """Each bad argument raises InvalidInputError naming it."""
    args: dict[str, object] = {"network": line_network([10.0] * 4),
                               "bank_probabilities": np.eye(5)[[1]],
                               "densities": np.eye(5)[[3]], **change}
    network, bank, dens = args.pop("network"), args.pop("bank_probabilities"), \
        args.pop("densities")
    with pytest.raises(InvalidInputError) as err:
        emd_matrix(network, bank, dens, **args)  # type: ignore[arg-type]
    assert err.value.field == field


# ----- exactness of the bounded road blocks ----------------------------------------------------

def _exact_matrix(net: RoadNetwork, p: np.ndarray, q: np.ndarray, mass: float) -> np.ndarray:
    """Every pair's EMD: the network simplex on SciPy's full Dijkstra distances."""
    dist = net.shortest_paths(np.arange(net.n_nodes))
    sig_p = [truncate_signature(row, mass) for row in p]
    sig_q = [truncate_signature(row, mass) for row in q]
    return np.array([[emd(a.weights, b.weights, dist[np.ix_(a.nodes, b.nodes)]).objective
                      for b in sig_q] for a in sig_p], dtype=float)


@pytest.mark.parametrize("seed", range(40))
def test_gated_entries_are_exact_on_random_graphs(seed: int) -> None:
    """On random road graphs and supports, each finite entry equals the exact EMD to 1e-9 and
    each +inf entry has an exact EMD ≥ the gate, whatever Dijkstra's limit cut off (odd seeds:
    the junction table instead of Dijkstra)."""
    rng = np.random.default_rng([seed, 17])
    net = random_network(int(rng.integers(4, 12)), float(rng.uniform(150.0, 600.0)), seed=seed)
    density = float(rng.uniform(0.02, 0.4))
    p = _rows(rng, int(rng.integers(1, 6)), net.n_nodes, density)
    q = _rows(rng, int(rng.integers(1, 6)), net.n_nodes, density)
    mass = float(rng.choice([0.9, 0.99, 1.0]))
    want = _exact_matrix(net, p, q, mass)
    metric = RoadMetric(net, dense_junction_limit=3000 * (seed % 2))  # Dijkstra or the table
    for gate in (float(np.quantile(want, 0.3)) * 1.01, float(np.quantile(want, 0.7)), math.inf):
        problem = EMDMatrixProblem.build(metric, p, q, support_mass=mass, gate_m=gate)
        result = solve_emd_matrix(problem)
        assert result.status is Status.OPTIMAL and result.plan is not None
        got = result.plan.costs
        finite = np.isfinite(got)
        np.testing.assert_allclose(got[finite], want[finite], rtol=1e-9, atol=1e-9)
        assert (want[~finite] >= gate * (1.0 - 1e-9)).all()


def test_capped_plans_are_refined_on_their_exact_blocks() -> None:
    """A plan that moves mass farther than Dijkstra's limit (2 × the gate) is solved again on
    exact distances: on a line, mass split between both ends against a point near one end."""
    net = line_network([10.0] * 20)
    p = np.zeros((1, 21))
    p[0, [0, 20]] = [0.9, 0.1]
    q = np.eye(21)[[2]]
    metric = RoadMetric(net, dense_junction_limit=0)  # no junction table: Dijkstra
    result = solve_emd_matrix(EMDMatrixProblem.build(metric, p, q, support_mass=1.0,
                                                     gate_m=80.0))
    assert result.plan is not None and result.stats["refined"] == 1.0
    assert result.plan.costs[0, 0] == pytest.approx(0.9 * 20.0 + 0.1 * 180.0, rel=1e-12)
