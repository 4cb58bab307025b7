"""The primal network simplex for uncapacitated min-cost flow, on explicit and bipartite arcs."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
from scipy.optimize import linprog

from searchtrack.core.deadline import Deadline
from searchtrack.estimate.transport import simplex
from searchtrack.estimate.transport.simplex import min_cost_flow

NO_LIMIT = Deadline(math.inf)


def _flows(solution: simplex.FlowSolution) -> dict[int, float]:
    """Arc index → flow of a solution."""
    return dict(zip(solution.arcs.tolist(), solution.amounts.tolist(), strict=True))


def _arcs(*arcs: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Tail and head arrays of ``(tail, head)`` pairs."""
    tail, head = zip(*arcs, strict=True)
    return np.array(tail, dtype=np.int64), np.array(head, dtype=np.int64)


def test_shortest_route_by_hand() -> None:
    """One unit from 0 to 2: via 1 (1 + 1) beats the direct arc (3)."""
    tail, head = _arcs((0, 1), (1, 2), (0, 2))
    sol = min_cost_flow(np.array([1.0, 0.0, -1.0]), np.array([1.0, 1.0, 3.0]), NO_LIMIT,
                        tail=tail, head=head)
    assert sol.status == "optimal" and sol.routed and sol.artificial_flow == 0.0
    assert _flows(sol) == {0: 1.0, 1: 1.0}


def test_bipartite_arcs_are_the_raveled_cost_matrix() -> None:
    """With ``ncols`` the arcs are the cells of the (rows × ncols) cost matrix, row-major: the
    diagonal of [[1, 10], [10, 1]] is arcs 0 and 3."""
    cost = np.array([[1.0, 10.0], [10.0, 1.0]]).ravel()
    sol = min_cost_flow(np.array([1.0, 2.0, -1.0, -2.0]), cost, NO_LIMIT, ncols=2)
    assert sol.status == "optimal" and _flows(sol) == {0: 1.0, 3: 2.0}


@pytest.mark.parametrize(("supply", "arcs"), [
    ([1.0, 0.0, -1.0], [(0, 1)]),  # node 2 unreachable
    ([1.0, 0.0, -1.0], [(2, 1), (1, 0)]),  # reachable only against the arcs' direction
])
def test_unreachable_demand_is_infeasible(supply: list[float],
                                          arcs: list[tuple[int, int]]) -> None:
    """Demand no directed path can reach stays on an artificial arc: infeasible, not routed."""
    tail, head = _arcs(*arcs)
    sol = min_cost_flow(np.array(supply), np.ones(len(arcs)), NO_LIMIT, tail=tail, head=head)
    assert sol.status == "infeasible" and not sol.routed
    assert sol.artificial_flow >= 1.0  # the unit of demand left on an artificial arc


def test_no_arcs_and_no_supply() -> None:
    """Without arcs a zero supply is optimal and an unbalanced one infeasible; a zero supply
    on arcs moves nothing."""
    none = np.zeros(0, dtype=np.int64)
    assert min_cost_flow(np.zeros(2), np.zeros(0), NO_LIMIT, tail=none, head=none).status == \
        "optimal"
    stuck = min_cost_flow(np.array([1.0, -1.0]), np.zeros(0), NO_LIMIT, tail=none, head=none)
    assert stuck.status == "infeasible" and stuck.pivots == 0
    tail, head = _arcs((0, 1), (1, 0))
    idle = min_cost_flow(np.zeros(2), np.ones(2), NO_LIMIT, tail=tail, head=head)
    assert idle.status == "optimal" and idle.arcs.size == 0


def test_an_expired_deadline_stops_before_any_pivot() -> None:
    """A deadline already past: status time_limit, no pivot, all mass still artificial."""
    spent = Deadline(1.0, started=time.perf_counter() - 10.0)
    sol = min_cost_flow(np.array([1.0, -1.0]), np.array([1.0]), spent, ncols=1)
    assert sol.status == "time_limit" and sol.pivots == 0 and not sol.routed
    assert sol.arcs.size == 0 and sol.artificial_flow >= 1.0


def test_round_off_is_judged_against_the_mass_scale() -> None:
    """Unrouted mass of 1e-12 is round-off for a unit mass scale, not for a scale of 1e-6."""
    supply = np.array([1.0, -1.0 + 1e-12])
    tail, head = _arcs((0, 1))
    assert min_cost_flow(supply, np.ones(1), NO_LIMIT, tail=tail, head=head).routed
    tight = min_cost_flow(supply, np.ones(1), NO_LIMIT, tail=tail, head=head, mass_scale=1e-6)
    assert not tight.routed and tight.status == "infeasible"


@pytest.mark.parametrize(("supply", "arcs", "unrouted"), [
    ([1.0, -1.0], [(1, 0)], 1.0),  # one unit against a one-way arc
    ([2.5, 0.0, -2.5], [(0, 1)], 2.5),  # node 2 unreachable
    ([3.0, -1.0, -2.0], [(0, 1)], 2.0),  # node 1 served, node 2 not
])
def test_unrouted_mass_is_counted_once(supply: list[float], arcs: list[tuple[int, int]],
                                       unrouted: float) -> None:
    """Each unrouted unit is reported once, not once leaving its source and once entering its
    sink."""
    tail, head = _arcs(*arcs)
    sol = min_cost_flow(np.array(supply), np.ones(len(arcs)), NO_LIMIT, tail=tail, head=head)
    assert sol.status == "infeasible" and sol.artificial_flow == pytest.approx(unrouted)


@pytest.mark.parametrize(("stuck", "routed"), [(0.6e-10, True), (1.5e-10, False)])
def test_round_off_tolerance_is_on_the_unrouted_mass(stuck: float, routed: bool) -> None:
    """Up to 1e-10 of a unit mass left unrouted (demand on an unreachable node) is round-off, as
    documented; more is not."""
    tail, head = _arcs((0, 1))
    sol = min_cost_flow(np.array([1.0, -1.0 + stuck, -stuck]), np.ones(1), NO_LIMIT,
                        tail=tail, head=head)
    assert sol.routed is routed
    assert sol.status == ("optimal" if routed else "infeasible")


@pytest.mark.parametrize("seed", range(6))
def test_random_transport_matches_highs(seed: int) -> None:
    """On random balanced 4×5 transportation problems the cost equals HiGHS's LP optimum and
    the flow meets every supply."""
    rng = np.random.default_rng(seed)
    m, n = 4, 5
    p = rng.integers(1, 6, m).astype(float)
    q = rng.random(n)
    q *= p.sum() / q.sum()
    cost = rng.uniform(0.0, 10.0, (m, n))
    sol = min_cost_flow(np.concatenate([p, -q]), cost.ravel(), NO_LIMIT, ncols=n)
    flow = np.zeros(m * n)
    flow[sol.arcs] = sol.amounts
    rows = np.kron(np.eye(m), np.ones((1, n)))
    cols = np.kron(np.ones((1, m)), np.eye(n))
    ref = linprog(cost.ravel(), A_eq=np.vstack([rows, cols]), b_eq=np.r_[p, q], method="highs")
    assert sol.status == "optimal" and ref.status == 0
    assert float(cost.ravel() @ flow) == pytest.approx(ref.fun, rel=1e-9)
    np.testing.assert_allclose(flow.reshape(m, n).sum(axis=1), p, rtol=1e-12)
    np.testing.assert_allclose(flow.reshape(m, n).sum(axis=0), q, rtol=1e-12)
    assert sol.arcs.size <= m + n - 1  # a basic solution


def test_warm_up_compiles_once() -> None:
    """warm_up() leaves the kernels marked ready, and a second call returns at once."""
    simplex.warm_up()
    assert simplex._WARM == [True]
    simplex.warm_up()
    assert simplex._WARM == [True]
