"""Earth Mover's Distance by backend name: between signatures with a cost matrix, or on a graph.

``emd`` solves the transportation LP (4.3)–(4.7) of thesis §4.3; ``emd_on_graph`` solves the
same distance under the graph's shortest-path metric as a min-cost flow on the graph's arcs
(no all-pairs distance matrix). Backends: ``"network"`` (exact primal network simplex, the fast
path), ``"lp"`` (the readable cvxpy LP, HiGHS simplex; exact but slow) and ``"auto"`` (network,
falling back to the LP if it fails). Every plan is re-checked against the marginals; a plan that
fails the check turns the result into ``ERROR``, never a silent wrong answer.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Callable
from typing import Any, TypeVar

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.registry import Backend, Registry, SolveFn, Stage, fallback_chain
from searchtrack.core.result import Result, Status
from searchtrack.core.types import FloatArray
from searchtrack.estimate.transport.lp import solve_graph_lp, solve_transport_lp
from searchtrack.estimate.transport.network import solve_graph_network, solve_transport_network
from searchtrack.estimate.transport.plan import GraphFlow, TransportPlan
from searchtrack.estimate.transport.problem import GraphProblem, TransportProblem
from searchtrack.estimate.transport.simplex import KERNEL_SET, warm_up
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.transport")

CHECK_RTOL = 1e-7  # marginals must hold to this fraction of the total flow (HiGHS's tolerance)

ProblemT = TypeVar("ProblemT", TransportProblem, GraphProblem)
PlanT = TypeVar("PlanT", TransportPlan, GraphFlow)


def transport_violations(problem: TransportProblem, plan: TransportPlan) -> list[str]:
    """How ``plan`` breaks (4.4)–(4.7) for ``problem``; empty when it is a valid plan."""
    m, n = problem.p.size, problem.q.size
    out = np.asarray(np.bincount(plan.rows, weights=plan.amounts, minlength=m), dtype=np.float64)
    into = np.asarray(np.bincount(plan.cols, weights=plan.amounts, minlength=n), dtype=np.float64)
    return _violations(problem.mass, out, into, problem.p, problem.q, plan.amounts,
                       problem.total_flow)


def graph_violations(problem: GraphProblem, plan: GraphFlow) -> list[str]:
    """How ``plan`` breaks flow conservation ``B f = p − q`` (bounds for partial EMD)."""
    net = plan.net_outflow()
    tol = CHECK_RTOL * problem.total_flow
    problems = [] if (plan.amounts >= 0).all() else ["negative flow"]
    if problem.mass == "partial":  # net = p' − q' with 0 ≤ p' ≤ p, 0 ≤ q' ≤ q
        return problems + _bounds("net outflow", net, -problem.q - tol, problem.p + tol)
    err = float(np.abs(net - (problem.p - problem.q)).max())
    return problems + ([f"flow conservation B f = p − q off by {err:.3g}"] if err > tol else [])


def _violations(mass: str, out: FloatArray, into: FloatArray, p: FloatArray, q: FloatArray,
                amounts: FloatArray, total: float) -> list[str]:
    tol = CHECK_RTOL * total
    problems = [] if (amounts >= 0).all() else ["negative flow (4.4)"]
    if mass == "partial":
        problems += _bounds("flow out of p (4.5)", out, np.zeros_like(p), p + tol)
        problems += _bounds("flow into q (4.6)", into, np.zeros_like(q), q + tol)
        flow = float(amounts.sum())  # plain floats: a NumPy scalar's repr names its type
        if abs(flow - total) > tol:
            problems.append(f"total flow {flow!r} != {float(total)!r} (4.7)")
        return problems
    for name, got, want in (("flow out of p (4.5)", out, p), ("flow into q (4.6)", into, q)):
        err = float(np.abs(got - want).max())
        if err > tol:
            problems.append(f"{name} off by {err:.3g}")
    return problems


def _bounds(name: str, got: FloatArray, low: FloatArray, high: FloatArray) -> list[str]:
    over = float(np.maximum(got - high, low - got).max())
    return [f"{name} outside its bounds by {over:.3g}"] if over > 0 else []


def _checked(result: Result[Any], problems: list[str]) -> Result[Any]:
    if not problems:
        return result
    log.error("emd: %s returned an invalid plan: %s", result.backend, problems)
    return dataclasses.replace(result, status=Status.ERROR, objective=None, bound=None,
                               plan=None, message="plan check failed: " + "; ".join(problems))


def _verified(backend: SolveFn[ProblemT, PlanT],
              check: Callable[[ProblemT, PlanT], list[str]]) -> SolveFn[ProblemT, PlanT]:
    """``backend`` whose every plan is checked independently (a rejected plan is an ERROR)."""
    def solve(problem: ProblemT, /, *, time_limit_s: float, seed: int) -> Result[PlanT]:
        result = backend(problem, time_limit_s=time_limit_s, seed=seed)
        return result if result.plan is None else _checked(result, check(problem, result.plan))

    return solve


def _auto(network: SolveFn[ProblemT, PlanT], lp: SolveFn[ProblemT, PlanT],
          check: Callable[[ProblemT, PlanT], list[str]]) -> SolveFn[ProblemT, PlanT]:
    """The network simplex, the LP if its checked answer is an ERROR."""
    stages = (Stage("network", _verified(network, check)), Stage("lp", _verified(lp, check)))

    def solve(problem: ProblemT, /, *, time_limit_s: float, seed: int) -> Result[PlanT]:
        return fallback_chain(problem, stages, time_limit_s=time_limit_s, seed=seed,
                              accept=_not_error)

    return solve


def _not_error(result: Result[Any]) -> bool:
    return result.status is not Status.ERROR


_NETWORK = _verified(solve_transport_network, transport_violations)
_LP = _verified(solve_transport_lp, transport_violations)
EMD_BACKENDS: Registry[TransportProblem, TransportPlan] = Registry("emd")
EMD_BACKENDS.register(Backend("auto", _auto(solve_transport_network, solve_transport_lp,
                                            transport_violations), True,
                              "network simplex; the cvxpy LP if it fails",
                              kernels=(KERNEL_SET,)))
EMD_BACKENDS.register(Backend("network", _NETWORK, True,
                              "primal network simplex on the bipartite graph of the supports",
                              kernels=(KERNEL_SET,)))
EMD_BACKENDS.register(Backend("lp", _LP, True,
                              "transportation LP (4.3)–(4.7) in cvxpy, HiGHS simplex"))

_GRAPH_NETWORK = _verified(solve_graph_network, graph_violations)
_GRAPH_LP = _verified(solve_graph_lp, graph_violations)
GRAPH_EMD_BACKENDS: Registry[GraphProblem, GraphFlow] = Registry("emd_on_graph")
GRAPH_EMD_BACKENDS.register(Backend("auto", _auto(solve_graph_network, solve_graph_lp,
                                                  graph_violations), True,
                                    "network simplex on the graph's arcs; the cvxpy LP if it "
                                    "fails", kernels=(KERNEL_SET,)))
GRAPH_EMD_BACKENDS.register(Backend("network", _GRAPH_NETWORK, True,
                                    "primal network simplex on the graph's arcs",
                                    kernels=(KERNEL_SET,)))
GRAPH_EMD_BACKENDS.register(Backend("lp", _GRAPH_LP, True,
                                    "min-cost flow LP B f = p − q in cvxpy, HiGHS simplex"))


def emd(
    p: ArrayLike,
    q: ArrayLike,
    cost: ArrayLike,
    *,
    mass: str = "normalize",
    backend: str = "auto",
    time_limit_s: float = 60.0,
) -> Result[TransportPlan]:
    """Earth Mover's Distance between signatures ``p`` and ``q`` (thesis §4.3, (4.3)–(4.7)).

    Parameters
    ----------
    p, q
        Non-negative weights of the two signatures (lengths m and n), e.g. a tracker prior and
        a measurement density on road nodes.
    cost
        ``(m, n)`` ground distances ``d_ig ≥ 0`` (metres), e.g. Dijkstra road distances.
    mass
        ``"normalize"`` (thesis (4.7): both scaled to unit mass), ``"partial"`` (Rubner's partial
        EMD: total flow ``min(Σp, Σq)``) or ``"equal"`` (masses must agree to 1e-9).
    backend
        ``"auto"``, ``"network"`` (exact network simplex) or ``"lp"`` (cvxpy, HiGHS).
    time_limit_s
        Wall-clock limit.

    Returns
    -------
    Result[TransportPlan]
        ``objective`` is the EMD ``work / total_flow``; ``sense`` is ``MINIMIZE``.

    Raises
    ------
    InvalidInputError
        Wrong shapes, negative or non-finite weights or costs, unequal masses with
        ``mass="equal"``, an unknown ``mass`` or ``backend``, a bad time limit.
    """
    return _solve(EMD_BACKENDS, TransportProblem.build(p, q, cost, mass), backend, time_limit_s)


def emd_on_graph(
    adjacency: object,
    p: ArrayLike,
    q: ArrayLike,
    *,
    mass: str = "normalize",
    backend: str = "auto",
    time_limit_s: float = 60.0,
) -> Result[GraphFlow]:
    """EMD between node weights ``p`` and ``q`` under the graph's shortest-path metric.

    Solved as the min-cost flow ``min Σ ℓ_e f_e  s.t.  B f = p − q,  f ≥ 0`` on the graph's own
    arcs, which equals :func:`emd` with the all-pairs Dijkstra distance matrix (W1 on a graph)
    without ever forming that matrix.

    Parameters
    ----------
    adjacency
        A :class:`~searchtrack.models.roads.RoadNetwork`, or a ``scipy.sparse`` ``(N, N)``
        matrix (CSR) of edge lengths in metres: each stored entry ``[i, j] = ℓ ≥ 0`` is an arc
        ``i → j``; symmetric for an undirected road network.
    p, q
        Non-negative weights on the N nodes.
    mass, backend, time_limit_s
        As for :func:`emd`.

    Returns
    -------
    Result[GraphFlow]
        ``objective`` is the EMD; ``INFEASIBLE`` when mass must cross between disconnected
        components.

    Raises
    ------
    InvalidInputError
        As for :func:`emd`, for ``adjacency`` instead of ``cost``.
    """
    if isinstance(adjacency, RoadNetwork):
        adjacency = adjacency.adjacency  # edge lengths (m), both ways
    return _solve(GRAPH_EMD_BACKENDS, GraphProblem.build(adjacency, p, q, mass), backend,
                  time_limit_s)


def _solve(registry: Registry[ProblemT, PlanT], problem: ProblemT, backend: str,
           time_limit_s: float) -> Result[PlanT]:
    """Solve with the kernels ready (compiled outside the clock); every backend's plan is
    checked once, inside the backend (:func:`_verified`)."""
    registry.checked(backend, problem, time_limit_s, 0)  # bad input first, then the warm-up
    warm_up()
    return registry.solve(backend, problem, time_limit_s=time_limit_s, seed=0)
