"""The CP-SAT model of the (team) OPTW: variables, routing, times and valid inequalities.

See :mod:`searchtrack.plan.optw.cpsat` for the formulation.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from ortools.sat.python import cp_model

from searchtrack.plan.optw.arcs import NEVER, ArcGraph, follow_gaps, shortest_gaps
from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.routes import idle_routes, schedule

MAX_SCALED_PROFIT = 2**50


@dataclass(frozen=True)
class Formulation:
    """Which strengthening the CP-SAT model gets, and the solver settings that go with it.

    The defaults are the measured best on the Solomon benchmark (``benchmarks/optw_cpsat.py
    --toggle`` flips one). ``single_share`` is the fraction of the time a team solve spends on the
    single-vehicle bound (0 switches it off); ``relation_cut_size`` sets CP-SAT's
    ``routing_cut_subset_size_for_binary_relation_bound`` (0 leaves CP-SAT's default).
    """

    budget: bool = True
    intervals: bool = True
    incompatibility: bool = True
    ordering: bool = False
    routes_for_single: bool = True
    linearization_level: int = 2
    probing_level: int = 2
    relation_cut_size: int = 12
    single_share: float = 0.3


def profit_scale(p: NDArray[np.float64]) -> tuple[NDArray[np.int64], int, float]:
    """Integer profits ``P``, the scale and the slack so that ``Σ p ≤ (Σ P + slack) / scale``."""
    total = float(p.sum())
    scale = 1
    for digits in range(7):
        scale = 10**digits
        if np.allclose(p * scale, np.round(p * scale), rtol=0.0, atol=1e-9):
            break
    while scale > 1 and total * scale > MAX_SCALED_PROFIT:
        scale //= 10
    scaled = np.round(p * scale)
    ints = scaled.astype(np.int64)
    slack = float(np.sum(np.maximum(p * scale - scaled, 0.0)))
    return ints, scale, slack


def scaled_bound(whole: int, scale: int, slack: float) -> float:
    """Upper bound in profit units from a bound on the scaled objective, rounded up."""
    if scale == 1 and slack == 0.0:
        return float(whole)
    return math.nextafter((whole + slack) / scale, math.inf)


@dataclass(eq=False)
class CpModel:
    """The CP-SAT model and what is needed to read a plan back from it."""

    model: cp_model.CpModel
    graph: ArcGraph
    arcs: list[cp_model.IntVar]
    visit: list[cp_model.IntVar]
    time: list[cp_model.IntVar]
    routes: cp_model.LinearExpr
    profit: NDArray[np.int64]
    scale: int
    slack: float


def build_model(instance: OPTWInstance, g: ArcGraph, form: Formulation) -> CpModel:
    """Variables, routing and timing constraints, valid inequalities and the objective."""
    k = g.size - 1
    model = cp_model.CpModel()
    arcs = [model.new_bool_var(f"x{a}_{b}") for a, b in zip(g.tails, g.heads, strict=True)]
    visit = [model.new_constant(1)] + [model.new_bool_var(f"y{j}") for j in range(1, k + 1)]
    time = [model.new_constant(int(g.earliest[0]))] + [
        model.new_int_var(int(g.earliest[j]), int(g.latest[j]), f"T{j}") for j in range(1, k + 1)
    ]
    routes = cp_model.LinearExpr.sum([lit for a, lit in zip(g.tails, arcs, strict=True) if a == 0])
    profit, scale, slack = profit_scale(instance.profit[g.vertices].astype(np.float64))
    mdl = CpModel(model, g, arcs, visit, time, routes, profit, scale, slack)
    _add_routing(mdl, instance.vehicles, form)
    _add_arc_times(mdl)
    if form.budget:
        horizon = int(g.latest[0] - g.earliest[0])
        model.add(cp_model.LinearExpr.weighted_sum(arcs, g.weight.tolist()) <= horizon * routes)
    if form.intervals:
        _add_intervals(mdl, instance.vehicles)
    if (form.incompatibility or form.ordering) and k > 1:
        _add_pair_cuts(mdl, instance, form)
    model.maximize(cp_model.LinearExpr.weighted_sum(visit[1:], profit.tolist()))
    return mdl


def _add_routing(mdl: CpModel, m: int, form: Formulation) -> None:
    """``AddCircuit`` for one vehicle, ``AddMultipleCircuit`` with ≤ m routes for a team."""
    g, model, k = mdl.graph, mdl.model, mdl.graph.size - 1
    circuit: list[cp_model.ArcT] = [
        (int(a), int(b), lit) for a, b, lit in zip(g.tails, g.heads, mdl.arcs, strict=True)
    ]
    circuit += [(j, j, ~mdl.visit[j]) for j in range(1, k + 1)]
    idle = model.new_bool_var("idle")
    if m == 1 and not form.routes_for_single:
        circuit.append((0, 0, idle))  # the empty route
        model.add_circuit(circuit)
    else:
        # One idle node keeps a route through the depot (CP-SAT's multiple circuit wants one);
        # it is used iff no real route is.
        circuit += [(0, k + 1, idle), (k + 1, 0, idle), (k + 1, k + 1, ~idle)]
        model.add_multiple_circuit(circuit)
        model.add(mdl.routes + idle >= 1)
        model.add(mdl.routes + m * idle <= m)
    if not g.empty_ok:
        model.add(idle == 0)
        model.add(mdl.routes == m)


def _add_arc_times(mdl: CpModel) -> None:
    """``x_ij ⇒ T_j ≥ T_i + δ_ij``; depot arcs fix the departure and bound the finish."""
    g, model, time = mdl.graph, mdl.model, mdl.time
    dep, finish = int(g.earliest[0]), int(g.latest[0])
    for a, b, dl, lit in zip(g.tails.tolist(), g.heads.tolist(), g.delta.tolist(), mdl.arcs,
                             strict=True):
        if b == 0:
            if g.latest[a] + dl > finish:
                model.add(time[a] + dl <= finish).only_enforce_if(lit)
        elif a == 0:
            if dep + dl > g.earliest[b]:
                model.add(time[b] >= dep + dl).only_enforce_if(lit)
        elif g.latest[a] + dl > g.earliest[b]:  # otherwise implied by the time bounds
            model.add(time[b] >= time[a] + dl).only_enforce_if(lit)


def _add_intervals(mdl: CpModel, m: int) -> None:
    """A vehicle is busy on ``[T_i, T_i + s_i + min_j t_ij)``: no overlap (m = 1) or ≤ m at once."""
    g, model = mdl.graph, mdl.model
    min_out = np.full(g.size, NEVER, dtype=np.int64)
    np.minimum.at(min_out, g.tails, g.delta)
    intervals = [
        model.new_optional_fixed_size_interval_var(
            mdl.time[j], int(min_out[j]), mdl.visit[j], f"I{j}"
        )
        for j in range(1, g.size)
        if min_out[j] < NEVER
    ]
    if m == 1:
        model.add_no_overlap(intervals)
    else:
        model.add_cumulative(intervals, [1] * len(intervals), m)


def _add_pair_cuts(mdl: CpModel, instance: OPTWInstance, form: Formulation) -> None:
    """Cuts from which customers can share a route, and in which order.

    Customers that no route can serve in either order clash: at most ``m`` customers of each
    clique of clashes are visited (greedy cliques, one grown from each customer). With
    ``form.ordering`` (one vehicle), when ``j`` cannot precede ``i``, serving both forces
    ``T_j ≥ T_i + D_ij``.
    """
    g, model, visit, m = mdl.graph, mdl.model, mdl.visit, instance.vehicles
    can = follow_gaps(instance, g) < NEVER  # can[a, b]: b can follow a on one route
    clash = ~can & ~can.T
    np.fill_diagonal(clash, False)
    clash[0, :] = clash[:, 0] = False
    if form.incompatibility:
        for clique in _cliques(clash, m + 1):
            if m == 1:
                model.add_at_most_one(visit[j] for j in clique)
            else:
                model.add(sum(visit[j] for j in clique) <= m)
    if form.ordering and m == 1:
        gaps = shortest_gaps(instance, g)
        for a, b in zip(*np.nonzero(can & ~can.T), strict=True):
            a, b = int(a), int(b)
            need = int(gaps[a - 1, b - 1])
            if g.latest[a] + need > g.earliest[b]:
                model.add(mdl.time[b] >= mdl.time[a] + need).only_enforce_if(
                    [visit[a], visit[b]]
                )


def _cliques(clash: NDArray[np.bool_], min_size: int) -> list[tuple[int, ...]]:
    """Greedy maximal cliques of the clash graph (one grown from each node), of ``min_size`` or
    more nodes, without duplicates."""
    found: set[tuple[int, ...]] = set()
    for v in np.flatnonzero(clash.any(axis=1)):
        clique = [int(v)]
        cand = clash[v].copy()
        while cand.any():
            idx = np.flatnonzero(cand)
            u = int(idx[np.argmax(clash[np.ix_(idx, idx)].sum(axis=1))])
            clique.append(u)
            cand &= clash[u]
        if len(clique) >= min_size:
            found.add(tuple(sorted(clique)))
    return sorted(found)


def add_hint(mdl: CpModel, instance: OPTWInstance, routes: Routes) -> int:
    """Hint ``routes`` to the solver; returns their scaled profit."""
    g = mdl.graph
    node = {int(v): j for j, v in enumerate(g.vertices, start=1)}
    end_index = None if instance.end is None else -1
    used: set[tuple[int, int]] = set()
    times: dict[int, int] = {}
    for r in routes:
        inner = [node[v] for v in r[1:end_index]]
        if not inner:
            continue
        starts = schedule(instance, r)
        for j, t in zip(inner, starts[1:], strict=False):
            times[j] = t
        path = [0, *inner, 0]
        used.update(itertools.pairwise(path))
    model = mdl.model
    for a, b, lit in zip(g.tails, g.heads, mdl.arcs, strict=True):
        model.add_hint(lit, (int(a), int(b)) in used)
    for j in range(1, g.size):
        model.add_hint(mdl.visit[j], j in times)
        model.add_hint(mdl.time[j], times.get(j, int(g.earliest[j])))
    return int(sum(int(mdl.profit[j - 1]) for j in times))


def read_routes(mdl: CpModel, solver: cp_model.CpSolver, instance: OPTWInstance) -> Routes:
    g = mdl.graph
    succ: dict[int, list[int]] = {}
    for a, b, lit in zip(g.tails, g.heads, mdl.arcs, strict=True):
        if solver.boolean_value(lit):
            succ.setdefault(int(a), []).append(int(b))
    routes: list[Route] = []
    tail: Route = () if instance.end is None else (instance.end,)
    for first in succ.get(0, []):
        path = [instance.start]
        j = first
        while j != 0:
            path.append(int(g.vertices[j - 1]))
            j = succ[j][0]
        routes.append((*path, *tail))
    routes += list(idle_routes(instance))[: instance.vehicles - len(routes)]
    return tuple(routes)


def scaled_profit(mdl: CpModel, routes: Routes) -> int:
    """Scaled objective of ``routes`` in the model's integer profits."""
    index = {int(v): j for j, v in enumerate(mdl.graph.vertices)}
    seen = {index[v] for r in routes for v in r if v in index}
    return int(sum(int(mdl.profit[j]) for j in seen))
