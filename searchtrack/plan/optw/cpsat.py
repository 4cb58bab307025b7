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

import logging
import math
from dataclasses import dataclass

import numpy as np
from ortools.sat.python import cp_model

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import watch
from searchtrack.core.result import Result, Status
from searchtrack.plan.optw.arcs import ArcGraph, arc_graph
from searchtrack.plan.optw.cpsat_model import (
    CpModel,
    Formulation,
    add_hint,
    build_model,
    profit_scale,
    read_routes,
    scaled_bound,
    scaled_profit,
)
from searchtrack.plan.optw.instance import OPTWInstance, Routes
from searchtrack.plan.optw.routes import (
    check_plan,
    idle_routes,
    initial_plan,
    routes_profit,
    schedule,
)

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
_MARGIN_S = 0.1  # CP-SAT overshoots its limit slightly while it winds down


def _proven_whole(
    solver: cp_model.CpSolver, native: cp_model.CpSolverStatus, mdl: CpModel, found: int | None
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
    p.catch_sigint_signal = False  # Ctrl-C is searchtrack's to handle (core.interrupt)


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
    mdl = build_model(instance, g, form)
    objective = cp_model.LinearExpr.weighted_sum(mdl.visit[1:], mdl.profit.tolist())
    if initial is not None:
        mdl.model.add(objective >= add_hint(mdl, instance, initial))
    if cap is not None:
        mdl.model.add(objective <= cap)
    solver = cp_model.CpSolver()
    _parameters(solver, max(stop.remaining() - _MARGIN_S, 0.01), seed, workers, form)
    with watch(solver.stop_search):  # Ctrl-C: stop the search, keep what it found
        native = solver.solve(mdl.model)
    name = solver.status_name(native)
    plan: Routes | None = None
    if native in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        plan = read_routes(mdl, solver, instance)
        check_plan(instance, plan, "CP-SAT plan")  # a modelling bug, never expected
    elif native == cp_model.UNKNOWN and initial is not None:
        plan = initial
    found = None if plan is None else scaled_profit(mdl, plan)
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
        _, scale, slack = profit_scale(instance.profit[g.vertices].astype(np.float64))
        bound = scaled_bound(run.whole, scale, slack)
        if status is Status.OPTIMAL and objective is not None and slack == 0.0:
            bound = objective
    message = (f"CP-SAT {run.name}; {g.size - 1} customers, {g.tails.size} arcs; "
               f"{run.branches} branches, {run.conflicts} conflicts{note}")
    _log.info("%s: %s objective=%s bound=%s", instance.name, message, objective, bound)
    return Result(status, objective, bound, deadline.elapsed(), BACKEND, run.plan,
                  message=message, stats={"customers": float(g.size - 1),
                                          "arcs": float(g.tails.size),
                                          "branches": float(run.branches)})
