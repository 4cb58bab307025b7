"""The readable reference: EMD as a linear program in cvxpy, solved exactly by HiGHS.

The transportation LP is written as in the thesis, (4.3)–(4.7); the graph version is the
min-cost flow ``min Σ ℓ_e f_e  s.t.  B f = p − q,  f ≥ 0`` with ``B`` the node–arc incidence
matrix. Both are solved by HiGHS's simplex inside SciPy (``solver=cp.SCIPY``), which returns a
vertex, i.e. an exact optimum; cvxpy's default Clarabel is an interior-point method accurate to
about 1e-6 only. Slow for large instances (a 1000 × 1000 transport LP takes tens of seconds):
use the network simplex for anything but checking.
"""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np
import scipy.sparse as sp

from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import FloatArray
from searchtrack.estimate.transport.plan import GraphFlow, TransportPlan
from searchtrack.estimate.transport.problem import GraphProblem, TransportProblem, is_balanced

BACKEND = "lp"


def _cvxpy() -> Any:
    """cvxpy, imported on first use (slow to import; only this backend needs it)."""
    import cvxpy

    return cvxpy


def map_status(native: str) -> Status:
    """Our status for a cvxpy status string (SciPy/HiGHS behind it); unknown ones are ERROR."""
    import cvxpy.settings as cp

    if native == cp.OPTIMAL:
        return Status.OPTIMAL
    if native == cp.OPTIMAL_INACCURATE:  # SciPy's "iteration or time limit reached"
        return Status.NO_SOLUTION
    if native in (cp.INFEASIBLE, cp.INFEASIBLE_INACCURATE):
        return Status.INFEASIBLE
    if native == cp.USER_LIMIT:
        return Status.NO_SOLUTION
    if native in (cp.UNBOUNDED, cp.UNBOUNDED_INACCURATE, cp.INFEASIBLE_OR_UNBOUNDED):
        return Status.ERROR  # impossible with costs >= 0: something is wrong
    if native == cp.SOLVER_ERROR:
        return Status.ERROR
    return Status.ERROR


def _solve(lp: Any, time_limit_s: float) -> tuple[Status, str]:
    cp = _cvxpy()
    # HiGHS's default feasibility tolerances (1e-7) let the optimum cheat on the marginals by
    # ~2e-9 relative on 5000-node graphs; at 1e-10 (its minimum) the vertex is exact.
    options: dict[str, Any] = {"method": "highs", "primal_feasibility_tolerance": 1e-10,
                               "dual_feasibility_tolerance": 1e-10}
    if math.isfinite(time_limit_s):
        options["time_limit"] = time_limit_s
    started = time.perf_counter()
    try:
        lp.solve(solver=cp.SCIPY, scipy_options=options)
    except cp.error.SolverError as exc:
        # cvxpy turns SciPy's "time limit reached, no x" into a solver error: tell them apart
        if time.perf_counter() - started >= 0.99 * time_limit_s:
            return Status.NO_SOLUTION, f"time limit of {time_limit_s:g} s reached ({exc})"
        return Status.ERROR, f"cvxpy SCIPY/HiGHS failed: {exc}"
    return map_status(lp.status), f"cvxpy SCIPY/HiGHS status {lp.status}"


def _failed(status: Status, message: str, started: float) -> Result[Any]:
    return Result(status, None, None, time.perf_counter() - started, BACKEND, None,
                  sense=Sense.MINIMIZE, message=message)


def _positive(values: Any) -> tuple[Any, FloatArray]:
    """Indices and values of the entries > 0 (HiGHS's round-off below zero is dropped)."""
    arr = np.asarray(values, dtype=np.float64)
    index = np.nonzero(arr > 0.0)
    return index, np.ascontiguousarray(arr[index])


def solve_transport_lp(
    problem: TransportProblem, /, *, time_limit_s: float, seed: int
) -> Result[TransportPlan]:
    """The transportation LP (4.3)–(4.7) in cvxpy. ``seed`` is unused (the solve is exact)."""
    cp = _cvxpy()

    started = time.perf_counter()
    cost, m, n = problem.cost, problem.p.size, problem.q.size
    flow = cp.Variable((m, n), nonneg=True)  # (4.4)
    out_of_p, into_q = cp.sum(flow, axis=1), cp.sum(flow, axis=0)
    if problem.mass == "partial":  # Rubner et al.: (4.5), (4.6) as <=, total flow (4.7) fixed
        constraints = [out_of_p <= problem.p, into_q <= problem.q,
                       cp.sum(flow) == problem.total_flow]
    else:  # (4.5), (4.6); (4.7) follows from them
        constraints = [out_of_p == problem.p, into_q == problem.q]
    lp = cp.Problem(cp.Minimize(cp.sum(cp.multiply(cost, flow))), constraints)  # (4.3)
    status, message = _solve(lp, time_limit_s)
    if not status.has_plan or flow.value is None:
        return _failed(status if not status.has_plan else Status.ERROR, message, started)
    (rows, cols), amounts = _positive(flow.value)
    work = float(cost[rows, cols] @ amounts)
    plan = TransportPlan(rows.astype(np.int64), cols.astype(np.int64), amounts, (m, n), work,
                         problem.total_flow)
    return Result(status, plan.emd, plan.emd, time.perf_counter() - started, BACKEND, plan,
                  sense=Sense.MINIMIZE, message=message, stats={"variables": float(m * n)})


def solve_graph_lp(
    problem: GraphProblem, /, *, time_limit_s: float, seed: int
) -> Result[GraphFlow]:
    """``min Σ ℓ_e f_e  s.t.  B f = sent − received, f ≥ 0`` in cvxpy; ``seed`` is unused.

    ``sent = p`` and ``received = q``, except for partial EMD, where the heavier side chooses
    how much of each weight to move, totalling ``min(Σp, Σq)``.
    """
    cp = _cvxpy()

    started = time.perf_counter()
    n, k = problem.n_nodes, problem.tails.size
    p, q, total = problem.p, problem.q, problem.total_flow
    # cvxpy constants, so that with no arcs ``sent == received`` is a constraint, not an array
    sent: Any = cp.Constant(p)
    received: Any = cp.Constant(q)
    constraints: list[Any] = []
    if problem.mass == "partial" and not is_balanced(float(p.sum()), float(q.sum())):
        part = cp.Variable(n, nonneg=True)
        constraints += [part <= (p if p.sum() > q.sum() else q), cp.sum(part) == total]
        if p.sum() > q.sum():
            sent = part
        else:
            received = part
    if k:
        arcs = np.arange(k)
        incidence = sp.csr_array(
            (np.r_[np.ones(k), -np.ones(k)], (np.r_[problem.tails, problem.heads],
                                               np.r_[arcs, arcs])), shape=(n, k))
        flow = cp.Variable(k, nonneg=True)
        constraints.append(incidence @ flow == sent - received)
        objective = cp.Minimize(problem.lengths @ flow)
    else:
        constraints.append(sent == received)
        objective = cp.Minimize(0)
    lp = cp.Problem(objective, constraints)
    status, message = _solve(lp, time_limit_s)
    if not status.has_plan or (k and flow.value is None):
        return _failed(status if not status.has_plan else Status.ERROR, message, started)
    if k:
        (index,), amounts = _positive(flow.value)
    else:
        index, amounts = np.zeros(0, dtype=np.int64), np.zeros(0)
    plan = GraphFlow(problem.tails[index], problem.heads[index], amounts, n,
                     float(problem.lengths[index] @ amounts), total)
    return Result(status, plan.emd, plan.emd, time.perf_counter() - started, BACKEND, plan,
                  sense=Sense.MINIMIZE, message=message, stats={"variables": float(k)})
