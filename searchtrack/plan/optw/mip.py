"""Reference integer program for the (team) OPTW, thesis (5.17)–(5.26), through OR-Tools + SCIP.

This is the readable model, kept close to the thesis (Barkley 2017, §5.5, after Vansteenwegen et
al.), extended to ``m`` vehicles with the **three-index** formulation of the team OPTW: ``x_ijk``
(vehicle ``k`` drives from ``i`` to ``j``), ``y_ik`` (vehicle ``k`` serves ``i``) and ``s_ik``
(its service start), with ``Σ_k y_ik ≤ 1`` as (5.22). With the thesis' errata applied:

* start and end are always on every route (``y_start = y_end = 1``), so an unused vehicle takes
  the direct arc start → end, which (5.18) as printed excluded; it exists only if it is feasible;
* no self-loops; nothing enters the start or leaves the end (5.19) because those arcs are absent;
* the end is a separate node even when ``end == start`` (its time is the arrival time, bounded by
  the latest finish), and an open end (``end=None``) is a dummy sink reached at zero travel from
  every vertex, so its time is the end of the last service;
* big-M per arc, ``M_ij = latest_i + T_i + c_ij − earliest_j`` (valid because service starts stay
  inside ``[earliest, latest]``; a constraint with ``M ≤ 0`` is dropped as implied);
* arcs and customers that no feasible route can use are eliminated first
  (:func:`searchtrack.plan.optw.arcs.arc_graph`);
* (5.23), the budget ``Σ (T_i y_ik + Σ_g c_ig x_igk) ≤ T_max``, is kept per vehicle with
  ``T_max = latest finish − departure`` (waiting is not in it, so the times do the exact check);
* vehicles are interchangeable, so idle vehicles come last: ``x_{SE,k} ≤ x_{SE,k+1}``.

It may be slow; it is the second opinion on the CP-SAT model, not the fast path.
"""

from __future__ import annotations

import itertools
import logging
import math
from dataclasses import dataclass

import numpy as np
from ortools.linear_solver import pywraplp

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import stop_requested, watch
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw.arcs import ArcGraph, arc_graph
from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes
from searchtrack.plan.optw.routes import (
    check_plan,
    idle_routes,
    initial_plan,
    routes_profit,
    schedule,
)

__all__ = ["solve_mip"]

_log = logging.getLogger("searchtrack.plan.optw.mip")

BACKEND = "mip"


@dataclass(eq=False)
class _Model:
    """The MIP, its variables per vehicle, and the graph they were built on."""

    solver: pywraplp.Solver
    graph: ArcGraph
    x: list[list[pywraplp.Variable]]  # x[k][a] for the arcs of the graph
    direct: list[pywraplp.Variable | None]  # x[k] of the arc start → end (None if infeasible)
    y: list[list[pywraplp.Variable]]  # y[k][j - 1] for customer node j
    s: list[list[pywraplp.Variable]]  # s[k][j - 1]; s[k][K] is the finish time


def _create_solver() -> tuple[pywraplp.Solver, str]:
    for name in ("SCIP", "CBC"):
        solver = pywraplp.Solver.CreateSolver(name)
        if solver is not None:
            return solver, name
    raise RuntimeError("OR-Tools has neither SCIP nor CBC")


def _build(instance: OPTWInstance, g: ArcGraph, solver: pywraplp.Solver) -> _Model:
    m, k_nodes = instance.vehicles, g.size - 1
    dep, finish = int(g.earliest[0]), int(g.latest[0])
    tails, heads = g.tails.tolist(), g.heads.tolist()
    direct_cost = int(instance.service[instance.start])
    if instance.end is not None:
        direct_cost += int(instance.travel[instance.start, instance.end])
    x: list[list[pywraplp.Variable]] = []
    direct: list[pywraplp.Variable | None] = []
    y: list[list[pywraplp.Variable]] = []
    s: list[list[pywraplp.Variable]] = []
    for k in range(m):
        # (5.26) binaries; (5.24)–(5.25) windows as bounds on s (tightened to earliest/latest).
        xk = [solver.BoolVar(f"x_{a}_{b}_{k}") for a, b in zip(tails, heads, strict=True)]
        dk = solver.BoolVar(f"x_S_E_{k}") if g.empty_ok else None
        yk = [solver.BoolVar(f"y_{j}_{k}") for j in range(1, k_nodes + 1)]
        sk = [solver.NumVar(float(g.earliest[j]), float(g.latest[j]), f"s_{j}_{k}")
              for j in range(1, k_nodes + 1)]
        sk.append(solver.NumVar(float(dep), float(finish), f"s_E_{k}"))
        x.append(xk)
        direct.append(dk)
        y.append(yk)
        s.append(sk)
        out_s = [xk[a] for a, t in enumerate(tails) if t == 0]
        in_e = [xk[a] for a, h in enumerate(heads) if h == 0]
        extra = [] if dk is None else [dk]
        # (5.18) every route leaves the start once and reaches the end once.
        solver.Add(solver.Sum(out_s + extra) == 1)
        solver.Add(solver.Sum(in_e + extra) == 1)
        # (5.20) flow conservation: in = out = y for each customer.
        ins: list[list[pywraplp.Variable]] = [[] for _ in range(k_nodes + 1)]
        outs: list[list[pywraplp.Variable]] = [[] for _ in range(k_nodes + 1)]
        for a, (t, h) in enumerate(zip(tails, heads, strict=True)):
            outs[t].append(xk[a])
            ins[h].append(xk[a])
        for j in range(1, k_nodes + 1):
            solver.Add(solver.Sum(ins[j]) == yk[j - 1])
            solver.Add(solver.Sum(outs[j]) == yk[j - 1])
        # (5.21) timing with per-arc big-M; node 0 is s = departure as a tail, s_E as a head.
        for a, (t, h) in enumerate(zip(tails, heads, strict=True)):
            delta = int(g.delta[a])
            tail_hi = dep if t == 0 else int(g.latest[t])
            head_lo = dep if h == 0 else int(g.earliest[h])
            big_m = tail_hi + delta - head_lo
            if big_m <= 0:
                continue
            s_tail = dep if t == 0 else sk[t - 1]
            s_head = sk[k_nodes] if h == 0 else sk[h - 1]
            solver.Add(s_tail + delta - s_head <= big_m * (1 - xk[a]))
        # (5.23) the budget per vehicle (travel and service, waiting excluded).
        cost = [int(d) * xk[a] for a, d in enumerate(g.delta.tolist())]
        if dk is not None:
            cost.append(direct_cost * dk)
        solver.Add(solver.Sum(cost) <= finish - dep)
    # (5.22) each customer at most once over all vehicles.
    for j in range(k_nodes):
        solver.Add(solver.Sum([y[k][j] for k in range(m)]) <= 1)
    # Symmetry: idle vehicles last.
    for k in range(m - 1):
        dk, dn = direct[k], direct[k + 1]
        if dk is not None and dn is not None:
            solver.Add(dk <= dn)
    # (5.17) total profit.
    profit = instance.profit[g.vertices].astype(float).tolist()
    solver.Maximize(solver.Sum([p * y[k][j] for k in range(m) for j, p in enumerate(profit)]))
    return _Model(solver, g, x, direct, y, s)


def _hint(mdl: _Model, instance: OPTWInstance, routes: Routes) -> None:
    g = mdl.graph
    node = {int(v): j for j, v in enumerate(g.vertices, start=1)}
    end_index = None if instance.end is None else -1
    variables: list[pywraplp.Variable] = []
    values: list[float] = []
    for k, r in enumerate(sorted(routes, key=lambda r: -len(r))):
        inner = [node[v] for v in r[1:end_index]]
        path = [0, *inner, 0]
        used = set(itertools.pairwise(path))
        for a, (t, h) in enumerate(zip(g.tails.tolist(), g.heads.tolist(), strict=True)):
            variables.append(mdl.x[k][a])
            values.append(1.0 if (t, h) in used else 0.0)
        d = mdl.direct[k]
        if d is not None:
            variables.append(d)
            values.append(0.0 if inner else 1.0)
        times = schedule(instance, r)
        on = dict(zip(inner, times[1:], strict=False))
        for j in range(1, g.size):
            variables += [mdl.y[k][j - 1], mdl.s[k][j - 1]]
            values += [1.0 if j in on else 0.0, float(on.get(j, int(g.earliest[j])))]
        variables.append(mdl.s[k][g.size - 1])
        values.append(float(times[-1]))
    mdl.solver.SetHint(variables, values)


def _read_routes(mdl: _Model, instance: OPTWInstance) -> Routes:
    g = mdl.graph
    tail: Route = () if instance.end is None else (instance.end,)
    routes: list[Route] = []
    for xk in mdl.x:
        succ = {int(g.tails[a]): int(g.heads[a]) for a, v in enumerate(xk)
                if v.solution_value() > 0.5}
        path = [instance.start]
        j = succ.get(0, 0)
        while j != 0 and len(path) <= g.size:
            path.append(int(g.vertices[j - 1]))
            j = succ.get(j, 0)
        routes.append((*path, *tail))
    return tuple(routes)


def _status(native: int, has_plan: bool) -> Status:
    """Map pywraplp's result status explicitly; anything unexpected is an ERROR."""
    if native == pywraplp.Solver.OPTIMAL:
        return Status.OPTIMAL
    if native == pywraplp.Solver.FEASIBLE:
        return Status.FEASIBLE
    if native == pywraplp.Solver.INFEASIBLE:
        return Status.INFEASIBLE
    if native == pywraplp.Solver.NOT_SOLVED:
        return Status.FEASIBLE if has_plan else Status.NO_SOLUTION
    if native == pywraplp.Solver.ABNORMAL and stop_requested():
        return Status.FEASIBLE if has_plan else Status.NO_SOLUTION  # interrupted on request
    if native in (pywraplp.Solver.UNBOUNDED, pywraplp.Solver.ABNORMAL,
                  pywraplp.Solver.MODEL_INVALID):
        return Status.ERROR
    return Status.ERROR


_NATIVE = {
    pywraplp.Solver.OPTIMAL: "OPTIMAL",
    pywraplp.Solver.FEASIBLE: "FEASIBLE",
    pywraplp.Solver.INFEASIBLE: "INFEASIBLE",
    pywraplp.Solver.UNBOUNDED: "UNBOUNDED",
    pywraplp.Solver.ABNORMAL: "ABNORMAL",
    pywraplp.Solver.MODEL_INVALID: "MODEL_INVALID",
    pywraplp.Solver.NOT_SOLVED: "NOT_SOLVED",
}


def solve_mip(
    instance: OPTWInstance,
    *,
    time_limit_s: float = 60.0,
    seed: int = 0,
    initial: Routes | None = None,
) -> Result[Routes]:
    """Solve the (team) OPTW with the thesis' integer program (5.17)–(5.26) and SCIP (or CBC).

    Parameters
    ----------
    instance
        The instance (``instance.vehicles`` routes).
    time_limit_s
        Wall-clock limit for building and solving.
    seed
        SCIP's random seed shift (CBC ignores it).
    initial
        A feasible plan (at most ``m`` routes), given to the solver as a hint.

    Returns
    -------
    Result
        ``OPTIMAL`` only when the solver proves it (relative gap 0); ``bound`` is its dual bound.

    Raises
    ------
    InvalidInputError
        For a non-positive time limit or an infeasible ``initial`` plan.
    """
    deadline = Deadline(check_time_limit(time_limit_s))
    if initial is not None:
        initial = initial_plan(instance, initial)
    g = arc_graph(instance)
    if g.size == 1:
        if g.empty_ok:
            return Result(Status.OPTIMAL, 0.0, 0.0, deadline.elapsed(), BACKEND,
                          idle_routes(instance), message="no customer is reachable")
        return Result(Status.INFEASIBLE, None, None, deadline.elapsed(), BACKEND, None,
                      message="no customer is reachable and the end cannot be reached in time")
    solver, engine = _create_solver()
    mdl = _build(instance, g, solver)
    if initial is not None:
        _hint(mdl, instance, initial)
    if engine == "SCIP":
        solver.SetSolverSpecificParametersAsString(
            f"randomization/randomseedshift = {int(seed) % 2**31}\n"
            "misc/catchctrlc = FALSE\n"  # Ctrl-C is core.interrupt's to handle
        )
    solver.SetNumThreads(1)
    solver.SetTimeLimit(max(1, int(deadline.remaining() * 1000) - 50))
    params = pywraplp.MPSolverParameters()
    params.SetDoubleParam(params.RELATIVE_MIP_GAP, 0.0)
    with watch(solver.InterruptSolve):  # Ctrl-C: SCIP stops and keeps its incumbent
        native = solver.Solve(params)
    name = f"{engine} {_NATIVE.get(native, str(native))}"
    plan: Routes | None = None
    if native in (pywraplp.Solver.OPTIMAL, pywraplp.Solver.FEASIBLE):
        plan = _read_routes(mdl, instance)
        try:
            check_plan(instance, plan, "plan")
        except InvalidInputError as exc:
            _log.error("%s returned an invalid plan: %s", engine, exc)
            return Result(Status.ERROR, None, None, deadline.elapsed(), BACKEND, None,
                          message=f"{name}: plan fails the schedule check: {exc}")
    elif native == pywraplp.Solver.NOT_SOLVED and initial is not None:
        plan = initial
    status = _status(native, plan is not None)
    objective = None if plan is None else routes_profit(instance, plan)
    bound: float | None = None
    if status.has_plan:
        raw = solver.Objective().BestBound()
        integral = bool(np.all(instance.profit == np.round(instance.profit)))
        if math.isfinite(raw) and abs(raw) < 1e19:  # SCIP reports "none" as ±1e20
            bound = float(math.floor(raw + 1e-6)) if integral else raw
        if status is Status.OPTIMAL and objective is not None:
            bound = max(objective, bound) if bound is not None else objective
    message = f"{name}; {g.size - 1} customers, {g.tails.size} arcs × {instance.vehicles}"
    _log.info("%s: %s objective=%s bound=%s", instance.name, message, objective, bound)
    return Result(status, objective, bound, deadline.elapsed(), BACKEND, plan, message=message)
