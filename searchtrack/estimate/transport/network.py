"""The fast exact path: EMD problems posed as uncapacitated min-cost flows for the network simplex.

* :func:`solve_transport_network`: the transportation problem on the complete bipartite graph
  of the two supports (zero weights dropped), the cost matrix used in place.
* :func:`solve_graph_network`: the flow on the road graph itself with supplies ``p − q``; the
  EMD under the shortest-path metric equals its cost (W1 as a Beckmann flow), with no distance
  matrix.

Partial EMD adds a zero-cost dummy that absorbs the excess of the heavier side: a dummy column
(or row) for the matrix; for the graph, each weighted node of the heavier side gets a copy that
holds its weight and sends it either into the graph or to the dummy.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.transport.plan import GraphFlow, TransportPlan
from searchtrack.estimate.transport.problem import GraphProblem, TransportProblem, is_balanced
from searchtrack.estimate.transport.simplex import FlowSolution, min_cost_flow

BACKEND = "network"


def map_status(solution: FlowSolution) -> Status:
    """Our status for the network simplex's native one; unknown ones are ERROR."""
    if solution.status == "optimal":
        return Status.OPTIMAL
    if solution.status == "infeasible":  # mass that no path can carry (disconnected graph)
        return Status.INFEASIBLE
    if solution.status == "time_limit":  # a valid flow only once no artificial arc carries mass
        return Status.FEASIBLE if solution.routed else Status.NO_SOLUTION
    if solution.status == "unbounded":  # impossible with costs >= 0: something is wrong
        return Status.ERROR
    return Status.ERROR


def _result(status: Status, plan: Any, solution: FlowSolution, started: float,
            stats: dict[str, float]) -> Result[Any]:
    message = (f"network simplex {solution.status} after {solution.pivots} pivots"
               + ("" if solution.routed else f"; unrouted mass {solution.artificial_flow:.3g}"))
    stats = {**stats, "pivots": float(solution.pivots)}
    runtime = time.perf_counter() - started
    if not status.has_plan:
        return Result(status, None, None, runtime, BACKEND, None, sense=Sense.MINIMIZE,
                      message=message, stats=stats)
    bound = plan.emd if status is Status.OPTIMAL else None
    return Result(status, plan.emd, bound, runtime, BACKEND, plan, sense=Sense.MINIMIZE,
                  message=message, stats=stats)


def solve_transport_network(
    problem: TransportProblem, /, *, time_limit_s: float, seed: int
) -> Result[TransportPlan]:
    """Network simplex on the transportation problem; ``seed`` is unused (deterministic)."""
    started = time.perf_counter()
    rows = np.flatnonzero(problem.p > 0.0)
    cols = np.flatnonzero(problem.q > 0.0)
    p, q = problem.p[rows], problem.q[cols]
    full = rows.size == problem.p.size and cols.size == problem.q.size
    cost = problem.cost if full else problem.cost[np.ix_(rows, cols)]
    total_p, total_q = float(p.sum()), float(q.sum())
    if problem.mass == "partial" and not is_balanced(total_p, total_q):
        if total_p > total_q:  # a dummy column takes what p cannot deliver, at no cost
            cost = np.hstack([cost, np.zeros((rows.size, 1))])
            q = np.append(q, total_p - total_q)
        else:
            cost = np.vstack([cost, np.zeros((1, cols.size))])
            p = np.append(p, total_q - total_p)
    ncols = q.size
    solution = min_cost_flow(np.concatenate([p, -q]), np.ascontiguousarray(cost).ravel(),
                             Deadline(time_limit_s), ncols=ncols, mass_scale=problem.total_flow)
    status = map_status(solution)
    i, j = solution.arcs // ncols, solution.arcs % ncols
    real = (i < rows.size) & (j < cols.size)
    r, c, amounts = rows[i[real]], cols[j[real]], solution.amounts[real]
    order = np.lexsort((c, r))
    r, c, amounts = r[order], c[order], amounts[order]
    work = float(problem.cost[r, c] @ amounts)
    plan = TransportPlan(r, c, amounts, problem.cost.shape, work, problem.total_flow)
    stats = {"rows": float(rows.size), "cols": float(cols.size)}
    return _result(status, plan, solution, started, stats)


def _partial_graph(problem: GraphProblem) -> tuple[FloatArray, IntArray, IntArray, FloatArray]:
    """Supplies and arcs of the graph flow, with copies and a dummy for partial EMD."""
    n, p, q = problem.n_nodes, problem.p, problem.q
    tails, heads, lengths = problem.tails, problem.heads, problem.lengths
    total_p, total_q = float(p.sum()), float(q.sum())
    if problem.mass != "partial" or is_balanced(total_p, total_q):
        return p - q, tails, heads, lengths
    heavy, light, sign = (p, q, 1.0) if total_p > total_q else (q, p, -1.0)
    support = np.flatnonzero(heavy > 0.0)
    copies = n + np.arange(support.size, dtype=np.int64)
    dummy = np.full(support.size, n + support.size, dtype=np.int64)
    excess = abs(total_p - total_q)
    supply = sign * np.concatenate([-light, heavy[support], [-excess]])
    # sources: copy -> node and copy -> dummy; sinks: the same arcs reversed
    new_tails = np.concatenate([copies, copies]) if sign > 0 else np.concatenate([support, dummy])
    new_heads = np.concatenate([support, dummy]) if sign > 0 else np.concatenate([copies, copies])
    return (supply, np.concatenate([tails, new_tails]), np.concatenate([heads, new_heads]),
            np.concatenate([lengths, np.zeros(2 * support.size)]))


def solve_graph_network(
    problem: GraphProblem, /, *, time_limit_s: float, seed: int
) -> Result[GraphFlow]:
    """Network simplex on the graph's own arcs; ``seed`` is unused (deterministic)."""
    started = time.perf_counter()
    supply, tails, heads, lengths = _partial_graph(problem)
    solution = min_cost_flow(supply, lengths, Deadline(time_limit_s), tail=tails, head=heads,
                             mass_scale=problem.total_flow)
    status = map_status(solution)
    keep = solution.arcs < problem.tails.size  # drop the copies' and the dummy's arcs
    order = np.argsort(solution.arcs[keep])
    arcs, amounts = solution.arcs[keep][order], solution.amounts[keep][order]
    plan = GraphFlow(problem.tails[arcs], problem.heads[arcs], amounts, problem.n_nodes,
                     float(problem.lengths[arcs] @ amounts), problem.total_flow)
    stats = {"nodes": float(problem.n_nodes), "arcs": float(problem.tails.size)}
    return _result(status, plan, solution, started, stats)
