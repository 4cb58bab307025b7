"""The least-cost starting basis of the network simplex on transportation problems: a feasible
spanning tree, and the same optimum as the artificial start and the LP."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import linprog

from searchtrack.core.deadline import Deadline
from searchtrack.estimate.transport.simplex import min_cost_flow
from searchtrack.estimate.transport.simplex_start import start_tree


def _problem(seed: int) -> tuple[np.ndarray, np.ndarray, int]:
    """Random masses and costs; every fourth with rounded costs (ties), every fifth with equal
    masses (degenerate: rows and columns run out together)."""
    rng = np.random.default_rng([seed, 47])
    m, n = int(rng.integers(1, 30)), int(rng.integers(1, 45))
    p, q = rng.random(m) + 1e-3, rng.random(n) + 1e-3
    if seed % 5 == 0:
        p, q = np.ones(m), np.ones(n)
    cost = rng.random((m, n)) * 400.0
    if seed % 4 == 0:
        cost = np.round(cost / 100.0) * 100.0
    p, q = p / p.sum(), q / q.sum()
    return np.concatenate([p, -q]), np.ascontiguousarray(cost.ravel()), n


def _lp(supply: np.ndarray, cost: np.ndarray, n: int) -> float:
    m = supply.size - n
    rows = np.kron(np.eye(m), np.ones(n))
    cols = np.kron(np.ones(m), np.eye(n))
    res = linprog(cost, A_eq=np.vstack([rows, cols]),
                  b_eq=np.concatenate([supply[:m], -supply[m:]]), bounds=(0, None),
                  method="highs")
    assert res.status == 0
    return float(res.fun)


@pytest.mark.parametrize("seed", range(60))
def test_the_start_is_a_feasible_spanning_tree(seed: int) -> None:
    """Every node hangs from the root through real arcs but row 0's, whose artificial arc
    carries only round-off; the tree flows meet every row's and column's mass."""
    supply, cost, ncols = _problem(seed)
    n, nrows, n_real = supply.size, supply.size - ncols, cost.size
    parent, pred = np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.int64)
    depth, first_child = np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.int64)
    next_sib, prev_sib = np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.int64)
    up, art_up = np.zeros(n + 1, dtype=np.int8), np.zeros(n, dtype=np.int8)
    flow, state = np.zeros(n + 1), np.ones(n_real, dtype=np.int8)
    assert start_tree(supply, cost, nrows, ncols, art_up, parent, pred, up, depth, flow,
                      first_child, next_sib, prev_sib, state, np.empty(n + 1, dtype=np.int64))
    assert parent[0] == n and pred[0] == n_real and abs(flow[0]) < 1e-12
    real = list(range(1, n))
    assert all(pred[u] < n_real for u in real) and (state == 0).sum() == n - 1
    out, into = np.zeros(nrows), np.zeros(ncols)
    for u in real:
        e = int(pred[u])
        assert state[e] == 0 and flow[u] >= 0.0
        out[e // ncols] += flow[u]
        into[e % ncols] += flow[u]
    np.testing.assert_allclose(out, supply[:nrows], atol=1e-12)
    np.testing.assert_allclose(into, -supply[nrows:], atol=1e-12)


@pytest.mark.parametrize("seed", range(60))
def test_the_optimum_is_the_artificial_starts_and_the_lps(seed: int) -> None:
    """Same EMD from the least-cost basis, from the artificial arcs and by HiGHS, to 1e-9."""
    supply, cost, ncols = _problem(seed)
    values = []
    for start in (True, False):
        sol = min_cost_flow(supply, cost, Deadline(math.inf), ncols=ncols, mass_scale=1.0,
                            least_cost_start=start)
        assert sol.status == "optimal" and sol.routed
        values.append(float(cost[sol.arcs] @ sol.amounts))
    assert values[0] == pytest.approx(values[1], rel=1e-9, abs=1e-9)
    assert values[0] == pytest.approx(_lp(supply, cost, ncols), rel=1e-9, abs=1e-9)
