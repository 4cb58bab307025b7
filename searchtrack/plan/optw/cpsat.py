"""Exact (team) OPTW with OR-Tools CP-SAT: a routes model strengthened by time-window reasoning.

Formulation (one model for every ``m``; vehicles are identical, so no vehicle index is needed):

* **Graph.** Node 0 is the depot: as a tail it is the start, as a head the end (or, for an open
  end, "stop here"). Nodes ``1..K`` are the customers some feasible route can visit
  (:func:`searchtrack.plan.optw.reach.reach`); an arc is kept only if the windows allow it
  (earliest start at the tail + service + travel ≤ latest start at the head). A skipped customer
  takes its self-loop. ``AddMultipleCircuit`` (CP-SAT's routes constraint) with at most ``m``
  arcs out of the depot has no vehicle symmetry at all; one idle node keeps a route through the
  depot when no vehicle drives. It is used for ``m = 1`` too: its routing cuts prove far more
  optima than ``AddCircuit`` (see the measurements in ``benchmarks/optw_cpsat.py``).
* **Times.** ``T_i`` (service start, ticks) lives in ``[earliest_i, latest_i]``; each arc
  enforces ``T_j ≥ T_i + s_i + t_ij`` (``OnlyEnforceIf``), depot arcs the departure and the
  finish limit. These also forbid subtours and feed CP-SAT's time-based routing cuts.
* **Valid inequalities** (switchable in :class:`Formulation`):
  the route-duration budget ``Σ w_ij x_ij ≤ (L − departure) · routes`` with
  ``w_ij = max(s_i + t_ij, earliest_j − latest_i)`` (waiting forced by the windows counts);
  a no-overlap (``m = 1``) or cumulative of capacity ``m`` over the optional intervals
  ``[T_i, T_i + s_i + min_j t_ij)`` (a vehicle is busy serving ``i`` and then travelling on);
  clique cuts ``Σ_{i∈C} y_i ≤ m`` over customers no route can serve in either order; optionally
  (off: not measured to help) ordering cuts ``y_i ∧ y_j ⇒ T_j ≥ T_i + D_ij`` for ``m = 1``.
  "Which order is possible" comes from a time-window aware earliest-arrival search from every
  customer, so no triangle inequality is assumed.
* **Team bound.** For ``m > 1`` a share of the time first solves the single-vehicle problem:
  every route is a feasible single route, so ``m`` × its proven bound caps the team objective.
* **Objective.** Profits are scaled to integers (exactly, by the least power of ten ≤ 10⁶ that
  makes them whole; otherwise ×10⁶ rounded, and the reported bound adds the rounding slack so it
  stays a valid upper bound in profit units).
"""

from __future__ import annotations

import itertools
import logging
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from ortools.sat.python import cp_model

from searchtrack.errors import InvalidInputError
from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.reach import reach
from searchtrack.plan.result import Result, Status
from searchtrack.plan.stop import Deadline, check_time_limit

__all__ = [
    "Formulation",
    "idle_routes",
    "initial_plan",
    "routes_profit",
    "schedule",
    "solve_cpsat",
]

_log = logging.getLogger("searchtrack.plan.optw.cpsat")

BACKEND = "cpsat"
_NEVER = np.iinfo(np.int64).max // 4
_MAX_SCALED_PROFIT = 2**50
_MARGIN_S = 0.1  # CP-SAT overshoots its limit slightly while it winds down


# ---------------------------------------------------------------------------------------------
# Route helpers shared with the MIP backend (independent of the solver model).


def idle_routes(instance: OPTWInstance) -> Routes:
    """``m`` unused routes: ``(start, end)``, or ``(start,)`` for an open end."""
    idle: Route = (instance.start,) if instance.end is None else (instance.start, instance.end)
    return (idle,) * instance.vehicles


def routes_profit(instance: OPTWInstance, routes: Routes) -> float:
    """Profit collected by ``routes`` (start and end excluded), in the instance's float profits."""
    end_index = None if instance.end is None else -1
    seen = {v for r in routes for v in r[1:end_index]}
    return float(sum(float(instance.profit[v]) for v in sorted(seen)))


def schedule(instance: OPTWInstance, route: Sequence[int]) -> tuple[int, ...]:
    """Service-start times (ticks) along ``route``; the last entry is the finish time.

    For a closed end the finish is the arrival at the end vertex; for an open end it is the end of
    the last service.

    Raises
    ------
    InvalidInputError
        If the route does not start (and end) where it must or breaks a window or the time limit.
    """
    inst = instance
    r = [int(v) for v in route]
    if not r or r[0] != inst.start:
        raise InvalidInputError("route", tuple(r), f"must start at vertex {inst.start}")
    inner = r[1:] if inst.end is None else r[1:-1]
    if inst.end is not None and (len(r) < 2 or r[-1] != inst.end):
        raise InvalidInputError("route", tuple(r), f"must end at vertex {inst.end}")
    customers = set(inst.customers.tolist())
    if any(v not in customers for v in inner) or len(set(inner)) != len(inner):
        raise InvalidInputError("route", tuple(r), "visits a non-customer or a customer twice")
    times = [inst.departure]
    for prev, v in itertools.pairwise(r):
        arrival = times[-1] + int(inst.service[prev]) + int(inst.travel[prev, v])
        if inst.end is not None and v == inst.end and len(times) == len(r) - 1:
            times.append(arrival)
            break
        begin = max(arrival, int(inst.open[v]))
        if begin > int(inst.close[v]):
            raise InvalidInputError(
                "route", tuple(r), f"reaches vertex {v} at {arrival}, after it closes "
                f"({int(inst.close[v])})"
            )
        times.append(begin)
    if inst.end is None:
        times.append(times[-1] + int(inst.service[r[-1]]))
    if times[-1] > inst.latest_finish:
        raise InvalidInputError(
            "route", tuple(r), f"finishes at {times[-1]}, after {inst.latest_finish}"
        )
    return tuple(times)


def initial_plan(instance: OPTWInstance, initial: Sequence[Sequence[int]]) -> Routes:
    """``initial`` as exactly ``m`` routes (idle ones appended), checked.

    Raises
    ------
    InvalidInputError
        Naming ``initial``, if it has too many routes or a route is infeasible.
    """
    routes = tuple(tuple(int(v) for v in r) for r in initial)
    if len(routes) > instance.vehicles:
        raise InvalidInputError("initial", routes, f"has more than {instance.vehicles} routes")
    routes += idle_routes(instance)[len(routes):]
    _check_plan(instance, routes, "initial")
    return routes


def _check_plan(instance: OPTWInstance, routes: Routes, name: str) -> None:
    if len(routes) != instance.vehicles:
        raise InvalidInputError(name, routes, f"needs exactly {instance.vehicles} routes")
    end_index = None if instance.end is None else -1
    inner = [v for r in routes for v in r[1:end_index]]
    if len(set(inner)) != len(inner):
        raise InvalidInputError(name, routes, "visits a customer on two routes")
    for r in routes:
        try:
            schedule(instance, r)
        except InvalidInputError as exc:
            raise InvalidInputError(name, routes, f"route {tuple(r)}: {exc.reason}") from None


# ---------------------------------------------------------------------------------------------
# Preprocessing: the arc graph and the time-window relations between customers.


@dataclass(frozen=True, eq=False)
class ArcGraph:
    """Customers worth modelling and the arcs some feasible route can use.

    Node 0 is the depot (the start as a tail, the end as a head); node ``k ≥ 1`` is vertex
    ``vertices[k - 1]``. ``delta[a]`` is the least time from the service start at the tail to the
    service start at the head (to the finish for arcs into node 0); ``weight[a]`` adds the waiting
    the windows force. ``earliest``/``latest`` bound the service start of each node (node 0:
    departure and latest finish).
    """

    vertices: NDArray[np.intp]
    earliest: NDArray[np.int64]
    latest: NDArray[np.int64]
    tails: NDArray[np.intp]
    heads: NDArray[np.intp]
    delta: NDArray[np.int64]
    weight: NDArray[np.int64]
    empty_ok: bool

    @property
    def size(self) -> int:
        """Number of nodes, depot included."""
        return int(self.vertices.size) + 1


def arc_graph(instance: OPTWInstance) -> ArcGraph:
    """Eliminate unreachable customers and arcs that no feasible route can use."""
    inst = instance
    r = reach(inst)
    verts = r.useful
    k = verts.size
    dep, limit = inst.departure, inst.latest_finish
    s = inst.service.astype(np.int64)
    earliest = np.concatenate(([dep], r.earliest[verts])).astype(np.int64)
    latest = np.concatenate(([limit], r.latest[verts])).astype(np.int64)
    # Customer-to-customer arcs straight from reach.
    sub = r.arc_ok[np.ix_(verts, verts)]
    ti, hi = np.nonzero(sub)
    tails = [ti + 1]
    heads = [hi + 1]
    delta = [s[verts[ti]] + inst.travel[verts[ti], verts[hi]]]
    # Start to customer.
    d0 = s[inst.start] + inst.travel[inst.start, verts]
    ok0 = np.maximum(dep + d0, inst.open[verts]) <= latest[1:]
    tails.append(np.zeros(int(ok0.sum()), dtype=np.intp))
    heads.append(np.flatnonzero(ok0) + 1)
    delta.append(d0[ok0])
    # Customer to end (or stop, for an open end).
    d1 = s[verts] if inst.end is None else s[verts] + inst.travel[verts, inst.end]
    ok1 = earliest[1:] + d1 <= limit
    tails.append(np.flatnonzero(ok1) + 1)
    heads.append(np.zeros(int(ok1.sum()), dtype=np.intp))
    delta.append(d1[ok1])
    if inst.end is None:
        empty_ok = dep + int(s[inst.start]) <= limit
    else:
        empty_ok = dep + int(s[inst.start]) + int(inst.travel[inst.start, inst.end]) <= limit
    t = np.concatenate(tails).astype(np.intp)
    h = np.concatenate(heads).astype(np.intp)
    d = np.concatenate(delta).astype(np.int64)
    if t.size:  # no route finishes later than its last service allows (finite for an open end)
        into = h == 0
        latest[0] = min(limit, int(np.max(latest[t[into]] + d[into], initial=dep)))
    tail_latest = np.where(t == 0, dep, latest[t])
    w = np.where(h == 0, d, np.maximum(d, earliest[h] - tail_latest))
    _log.debug("arc graph: %d of %d customers, %d arcs", k, inst.customers.size, t.size)
    return ArcGraph(verts, earliest, latest, t, h, d, w, empty_ok)


def _after(instance: OPTWInstance, g: ArcGraph) -> NDArray[np.int64]:
    """``E[a, b]``: earliest service start at node ``b`` on a route that serves ``a`` before it.

    Time-window aware forward search from every customer ``a`` started at ``earliest[a]``
    (waiting allowed, so arrival times are FIFO); ``_NEVER`` where ``b`` cannot follow ``a``.
    Only customer nodes ``1..K`` are filled.
    """
    k = g.size - 1
    inst = instance
    v = g.vertices
    step = inst.service[v][:, None] + inst.travel[np.ix_(v, v)]
    np.fill_diagonal(step, _NEVER)
    opn, lat = inst.open[v], g.latest[1:]
    out = np.full((g.size, g.size), _NEVER, dtype=np.int64)
    for a in range(k):
        best = np.full(k, _NEVER, dtype=np.int64)
        done = np.zeros(k, dtype=bool)
        best[a] = g.earliest[a + 1]
        while True:
            cand = np.where(done, _NEVER, best)
            u = int(np.argmin(cand))
            if cand[u] >= _NEVER:
                break
            done[u] = True
            arr = np.maximum(best[u] + step[u], opn)
            ok = (arr <= lat) & ~done & (arr < best)
            best = np.where(ok, arr, best)
        best[a] = _NEVER  # a itself does not follow a
        out[a + 1, 1:] = best
    return out


def _shortest_gaps(instance: OPTWInstance, g: ArcGraph) -> NDArray[np.int64]:
    """``D[a, b]``: least service-start-to-service-start time from ``a`` to ``b`` (any path)."""
    v = g.vertices
    d = (instance.service[v][:, None] + instance.travel[np.ix_(v, v)]).astype(np.int64)
    for m in range(v.size):
        d = np.minimum(d, d[:, m : m + 1] + d[m : m + 1, :])
    return d


# ---------------------------------------------------------------------------------------------
# The model.


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


def _profit_scale(p: NDArray[np.float64]) -> tuple[NDArray[np.int64], int, float]:
    """Integer profits ``P``, the scale and the slack so that ``Σ p ≤ (Σ P + slack) / scale``."""
    total = float(p.sum())
    scale = 1
    for digits in range(7):
        scale = 10**digits
        if np.allclose(p * scale, np.round(p * scale), rtol=0.0, atol=1e-9):
            break
    while scale > 1 and total * scale > _MAX_SCALED_PROFIT:
        scale //= 10
    scaled = np.round(p * scale)
    ints = scaled.astype(np.int64)
    slack = float(np.sum(np.maximum(p * scale - scaled, 0.0)))
    return ints, scale, slack


def _bound(whole: int, scale: int, slack: float) -> float:
    """Upper bound in profit units from a bound on the scaled objective, rounded up."""
    if scale == 1 and slack == 0.0:
        return float(whole)
    return math.nextafter((whole + slack) / scale, math.inf)


@dataclass(eq=False)
class _Model:
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


def _build(instance: OPTWInstance, g: ArcGraph, form: Formulation) -> _Model:
    """Variables, routing and timing constraints, valid inequalities and the objective."""
    k = g.size - 1
    model = cp_model.CpModel()
    arcs = [model.new_bool_var(f"x{a}_{b}") for a, b in zip(g.tails, g.heads, strict=True)]
    visit = [model.new_constant(1)] + [model.new_bool_var(f"y{j}") for j in range(1, k + 1)]
    time = [model.new_constant(int(g.earliest[0]))] + [
        model.new_int_var(int(g.earliest[j]), int(g.latest[j]), f"T{j}") for j in range(1, k + 1)
    ]
    routes = cp_model.LinearExpr.sum([lit for a, lit in zip(g.tails, arcs, strict=True) if a == 0])
    profit, scale, slack = _profit_scale(instance.profit[g.vertices].astype(np.float64))
    mdl = _Model(model, g, arcs, visit, time, routes, profit, scale, slack)
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


def _add_routing(mdl: _Model, m: int, form: Formulation) -> None:
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


def _add_arc_times(mdl: _Model) -> None:
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


def _add_intervals(mdl: _Model, m: int) -> None:
    """A vehicle is busy on ``[T_i, T_i + s_i + min_j t_ij)``: no overlap (m = 1) or ≤ m at once."""
    g, model = mdl.graph, mdl.model
    min_out = np.full(g.size, _NEVER, dtype=np.int64)
    np.minimum.at(min_out, g.tails, g.delta)
    intervals = [
        model.new_optional_fixed_size_interval_var(
            mdl.time[j], int(min_out[j]), mdl.visit[j], f"I{j}"
        )
        for j in range(1, g.size)
        if min_out[j] < _NEVER
    ]
    if m == 1:
        model.add_no_overlap(intervals)
    else:
        model.add_cumulative(intervals, [1] * len(intervals), m)


def _add_pair_cuts(mdl: _Model, instance: OPTWInstance, form: Formulation) -> None:
    """Cuts from which customers can share a route, and in which order.

    Customers that no route can serve in either order clash: at most ``m`` customers of each
    clique of clashes are visited (greedy cliques, one grown from each customer). With
    ``form.ordering`` (one vehicle), when ``j`` cannot precede ``i``, serving both forces
    ``T_j ≥ T_i + D_ij``.
    """
    g, model, visit, m = mdl.graph, mdl.model, mdl.visit, instance.vehicles
    can = _after(instance, g) < _NEVER  # can[a, b]: b can follow a on one route
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
        gaps = _shortest_gaps(instance, g)
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


def _hint(mdl: _Model, instance: OPTWInstance, routes: Routes) -> int:
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


def _read_routes(mdl: _Model, solver: cp_model.CpSolver, instance: OPTWInstance) -> Routes:
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


def _scaled(mdl: _Model, routes: Routes) -> int:
    """Scaled objective of ``routes`` in the model's integer profits."""
    index = {int(v): j for j, v in enumerate(mdl.graph.vertices)}
    seen = {index[v] for r in routes for v in r if v in index}
    return int(sum(int(mdl.profit[j]) for j in seen))


def _proven_whole(
    solver: cp_model.CpSolver, native: cp_model.CpSolverStatus, mdl: _Model, found: int | None
) -> int:
    """CP-SAT's upper bound on the scaled objective, or the total profit when it has none.

    CP-SAT reports 0 as its bound when stopped before the search starts (e.g. in presolve), so a
    bound is trusted only at OPTIMAL or when it lies strictly above the plan in hand.
    """
    total = int(mdl.profit.sum())
    raw = solver.best_objective_bound
    if native == cp_model.OPTIMAL:
        return round(solver.objective_value)
    if found is not None and math.isfinite(raw) and raw > found + 0.5:
        return min(total, math.floor(raw + 1e-6))
    return total


def _parameters(
    solver: cp_model.CpSolver, time_limit_s: float, seed: int, workers: int, form: Formulation
) -> None:
    p = solver.parameters
    p.max_time_in_seconds = time_limit_s
    p.random_seed = seed
    p.num_workers = workers
    p.linearization_level = form.linearization_level
    p.cp_model_probing_level = form.probing_level
    if form.relation_cut_size > 0:
        p.routing_cut_subset_size_for_binary_relation_bound = form.relation_cut_size
        p.routing_cut_subset_size_for_tight_binary_relation_bound = min(
            form.relation_cut_size, 8
        )
    p.log_search_progress = False


def _status(native: cp_model.CpSolverStatus, has_plan: bool) -> Status:
    """Map CP-SAT's status explicitly; anything unexpected is an ERROR."""
    if native == cp_model.OPTIMAL:
        return Status.OPTIMAL
    if native == cp_model.FEASIBLE:
        return Status.FEASIBLE
    if native == cp_model.INFEASIBLE:
        return Status.INFEASIBLE
    if native == cp_model.UNKNOWN:
        return Status.FEASIBLE if has_plan else Status.NO_SOLUTION
    if native == cp_model.MODEL_INVALID:
        return Status.ERROR
    return Status.ERROR


@dataclass(frozen=True)
class _Run:
    """What one CP-SAT solve produced."""

    native: cp_model.CpSolverStatus
    name: str
    plan: Routes | None
    found: int | None  # scaled objective of ``plan``
    whole: int  # proven upper bound on the scaled objective
    branches: int
    conflicts: int


def _run(
    instance: OPTWInstance,
    g: ArcGraph,
    form: Formulation,
    stop: Deadline,
    seed: int,
    workers: int,
    initial: Routes | None,
    cap: int | None,
) -> _Run:
    """Build and solve one model by ``stop``; ``cap`` bounds the scaled objective from above."""
    mdl = _build(instance, g, form)
    objective = cp_model.LinearExpr.weighted_sum(mdl.visit[1:], mdl.profit.tolist())
    if initial is not None:
        mdl.model.add(objective >= _hint(mdl, instance, initial))
    if cap is not None:
        mdl.model.add(objective <= cap)
    solver = cp_model.CpSolver()
    _parameters(solver, max(stop.remaining() - _MARGIN_S, 0.01), seed, workers, form)
    native = solver.solve(mdl.model)
    name = solver.status_name(native)
    plan: Routes | None = None
    if native in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        plan = _read_routes(mdl, solver, instance)
        _check_plan(instance, plan, "CP-SAT plan")  # a modelling bug, never expected
    elif native == cp_model.UNKNOWN and initial is not None:
        plan = initial
    found = None if plan is None else _scaled(mdl, plan)
    whole = _proven_whole(solver, native, mdl, found)
    if cap is not None:
        whole = min(whole, cap)
    return _Run(native, name, plan, found, whole, solver.num_branches, solver.num_conflicts)


def _route_cap(
    instance: OPTWInstance,
    g: ArcGraph,
    form: Formulation,
    deadline: Deadline,
    seed: int,
    workers: int,
    initial: Routes | None,
) -> tuple[int | None, str]:
    """``m`` × a proven bound on one route's scaled profit, from a single-vehicle solve."""
    single = instance.with_vehicles(1)
    best: Routes | None = None
    if initial is not None:
        best = (max(initial, key=lambda r: routes_profit(single, (r,))),)
    one = _run(single, g, form, deadline.sub(form.single_share), seed, workers, best, None)
    if one.native == cp_model.INFEASIBLE:
        return None, "single vehicle INFEASIBLE"
    return instance.vehicles * one.whole, f"single vehicle {one.name} ≤ {one.whole}"


def solve_cpsat(
    instance: OPTWInstance,
    *,
    time_limit_s: float = 60.0,
    seed: int = 0,
    initial: Routes | None = None,
    workers: int = 2,
    formulation: Formulation | None = None,
) -> Result[Routes]:
    """Solve the (team) OPTW exactly with CP-SAT, or report the best plan and bound in time.

    Parameters
    ----------
    instance
        The instance (``instance.vehicles`` routes).
    time_limit_s
        Wall-clock limit for preprocessing, model building and search.
    seed
        CP-SAT ``random_seed``; with ``workers=1`` the search is fully deterministic.
    initial
        A feasible plan (e.g. from a heuristic; at most ``m`` routes, idle ones may be left
        out): hinted to the solver and used as a lower bound.
    workers
        CP-SAT worker threads.
    formulation
        Which valid inequalities to add (defaults to the measured best).

    Returns
    -------
    Result
        ``OPTIMAL`` only when proven; ``bound`` is the proven upper bound on profit (CP-SAT's,
        for a team also ``m`` × the single-vehicle bound, or the total reachable profit when
        CP-SAT was stopped before proving any).

    Raises
    ------
    InvalidInputError
        For a non-positive time limit, fewer than one worker or an infeasible ``initial`` plan.
    """
    deadline = Deadline(check_time_limit(time_limit_s))
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InvalidInputError("workers", workers, "must be an integer ≥ 1")
    if initial is not None:
        initial = initial_plan(instance, initial)
    form = formulation or Formulation()
    g = arc_graph(instance)
    if g.size == 1:
        if g.empty_ok:
            return Result(Status.OPTIMAL, 0.0, 0.0, deadline.elapsed(), BACKEND,
                          idle_routes(instance), message="no customer is reachable")
        return Result(Status.INFEASIBLE, None, None, deadline.elapsed(), BACKEND, None,
                      message="no customer is reachable and the end cannot be reached in time")
    cap, note = None, ""
    try:
        if instance.vehicles > 1 and form.single_share > 0:
            cap, note = _route_cap(instance, g, form, deadline, seed, workers, initial)
            note = f"; {note}"
        run = _run(instance, g, form, deadline, seed, workers, initial, cap)
    except InvalidInputError as exc:
        _log.error("CP-SAT returned an invalid plan: %s", exc)
        return Result(Status.ERROR, None, None, deadline.elapsed(), BACKEND, None,
                      message=f"CP-SAT plan fails the schedule check: {exc}")
    return _result(instance, g, run, deadline, note)


def _result(
    instance: OPTWInstance, g: ArcGraph, run: _Run, deadline: Deadline, note: str
) -> Result[Routes]:
    """Map a run to the shared result: explicit status, profit recomputed, bound in profit units."""
    status = _status(run.native, run.plan is not None)
    if run.found is not None and run.found >= run.whole and status.has_plan:
        status = Status.OPTIMAL  # the plan meets a proven bound (e.g. the single-vehicle cap)
    objective = None if run.plan is None else routes_profit(instance, run.plan)
    bound: float | None = None
    if status in (Status.OPTIMAL, Status.FEASIBLE, Status.NO_SOLUTION):
        _, scale, slack = _profit_scale(instance.profit[g.vertices].astype(np.float64))
        bound = _bound(run.whole, scale, slack)
        if status is Status.OPTIMAL and objective is not None and slack == 0.0:
            bound = objective
    message = (f"CP-SAT {run.name}; {g.size - 1} customers, {g.tails.size} arcs; "
               f"{run.branches} branches, {run.conflicts} conflicts{note}")
    _log.info("%s: %s objective=%s bound=%s", instance.name, message, objective, bound)
    return Result(status, objective, bound, deadline.elapsed(), BACKEND, run.plan,
                  message=message, stats={"customers": float(g.size - 1),
                                          "arcs": float(g.tails.size),
                                          "branches": float(run.branches)})
