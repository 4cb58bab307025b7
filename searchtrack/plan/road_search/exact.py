"""The receding-horizon path choice as a maximum coverage integer program, solved by CP-SAT.

On the time-expanded graphs (:mod:`~searchtrack.plan.road_search.scenario`), with ``x_{q,a}``
"UAV ``q`` flies arc ``a``" and ``X_k`` "some UAV flies element ``k``"::

    max  Σ_g V_g max_{k flown, k sees g} β_k
    s.t. Σ_{a leaves the start} x_{q,a} = 1                     (one path per UAV)
         Σ_{a enters σ} x_{q,a} = Σ_{a leaves σ} x_{q,a}        (flow, every inner state σ)
         X_k ≤ Σ_{q, a flies k} x_{q,a}

The maximum is written with nested covers: if group ``g``'s sightings have the distinct values
``b_1 > b_2 > … > b_J`` (``b_{J+1} = 0``), its value is ``Σ_j V_g (b_j − b_{j+1}) u_{g,j}`` with
``u_{g,j} ≤ Σ_{k sees g, β_k ≥ b_j} X_k`` binary (each group counts once, at its best sighting).
Groups with the same element set share one ``u`` (their coefficients add up), and a set of one
element puts its coefficient on ``X_k`` itself. Coefficients are scaled by ``S`` (the
scenario's upper bound maps to :data:`SCALE_TOP`) and rounded up, so CP-SAT's bound divided by
``S`` is a valid bound on the true optimum; the plan's objective is recomputed exactly, and the
answer is ``OPTIMAL`` when it meets that bound within a relative :data:`REL_TOL`. CP-SAT runs
with one worker and linearization level 2 (measured fastest on the paper's grid), deterministic
for a seed; it stops at the time limit and on a stop request
(:func:`~searchtrack.core.interrupt.watch`), keeping the best plan found and the bound.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from ortools.sat.python import cp_model

from searchtrack.core.deadline import Deadline
from searchtrack.core.interrupt import watch
from searchtrack.core.result import Result, Status
from searchtrack.core.types import IntArray
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem, meets_bound
from searchtrack.plan.road_search.scenario import Scenario

#: The scenario's upper bound is scaled to this many integer units.
SCALE_TOP = 1e10

#: Relative tolerance of the optimality proof (rounding of the scaled values).
REL_TOL = 1e-7


@dataclass(frozen=True)
class CoverageModel:
    """A built CP-SAT model: the arc variables per UAV, the element variables, the nested
    cover variables (keyed by their element sets) and the objective scale."""

    model: cp_model.CpModel
    x: tuple[list[cp_model.IntVar], ...]
    element: dict[int, cp_model.IntVar]
    nested: dict[tuple[int, ...], cp_model.IntVar]
    scale: float


def nested_covers(scenario: Scenario) -> dict[tuple[int, ...], float]:
    """``{element set: coefficient}``: every group's nested covers, coefficients summed over
    the groups that share a set (module docstring)."""
    coefficient: dict[tuple[int, ...], float] = {}
    cover = scenario.cover
    for g in range(scenario.n_groups):
        ks = np.flatnonzero(cover[:, g])
        beta = cover[ks, g]
        levels = np.unique(beta)[::-1]  # distinct values, best first
        nxt = np.append(levels[1:], 0.0)
        for b, b_next in zip(levels.tolist(), nxt.tolist(), strict=True):
            key = tuple(ks[beta >= b].tolist())
            coefficient[key] = coefficient.get(key, 0.0) + float(
                scenario.group_value[g]) * (b - b_next)
    return coefficient


def build_model(scenario: Scenario) -> CoverageModel:
    """The integer program of the module docstring for ``scenario``."""
    model = cp_model.CpModel()
    ub = scenario.upper_bound()
    scale = SCALE_TOP / ub if ub > 0.0 else 1.0
    xs: list[list[cp_model.IntVar]] = []
    flown: dict[int, list[cp_model.IntVar]] = {}
    for q, lat in enumerate(scenario.lattices):
        x = [model.new_bool_var(f"x{q}_{a}") for a in range(lat.n_arcs)]
        xs.append(x)
        model.add(sum(x[a] for a in range(int(lat.out_ptr[0]), int(lat.out_ptr[1]))) == 1)
        inbound: list[list[int]] = [[] for _ in range(lat.n_states)]
        for a, h in enumerate(lat.arc_head.tolist()):
            inbound[h].append(a)
        for state in range(1, lat.n_states):
            out = range(int(lat.out_ptr[state]), int(lat.out_ptr[state + 1]))
            if len(out):
                model.add(sum(x[a] for a in inbound[state]) == sum(x[a] for a in out))
        for a, k in enumerate(lat.arc_element.tolist()):
            flown.setdefault(k, []).append(x[a])
    element: dict[int, cp_model.IntVar] = {}
    for k, arcs in flown.items():
        element[k] = model.new_bool_var(f"X{k}")
        model.add(element[k] <= sum(arcs))
    nested: dict[tuple[int, ...], cp_model.IntVar] = {}
    terms = []
    for key, c in nested_covers(scenario).items():
        if len(key) == 1:
            var = element[key[0]]
        else:
            var = model.new_bool_var(f"u{len(nested)}")
            model.add(var <= sum(element[k] for k in key))
            nested[key] = var
        terms.append(math.ceil(c * scale) * var)
    model.maximize(sum(terms))
    return CoverageModel(model, tuple(xs), element, nested, scale)


def _hint(mdl: CoverageModel, scenario: Scenario, plan: RoadPlan) -> None:
    """Hint every variable from ``plan``."""
    chosen = [set(scenario.arcs_of(q, p).tolist()) for q, p in enumerate(plan.edges)]
    for q, x in enumerate(mdl.x):
        for a, var in enumerate(x):
            mdl.model.add_hint(var, a in chosen[q])
    flown = set(scenario.elements_of(plan).tolist())
    for k, var in mdl.element.items():
        mdl.model.add_hint(var, k in flown)
    for key, var in mdl.nested.items():
        mdl.model.add_hint(var, any(k in flown for k in key))


def _read(mdl: CoverageModel, scenario: Scenario, solver: cp_model.CpSolver) -> RoadPlan:
    arcs: list[IntArray] = []
    for q, lat in enumerate(scenario.lattices):
        state, path = 0, []
        for _ in range(int(lat.state_level.max())):
            out = range(int(lat.out_ptr[state]), int(lat.out_ptr[state + 1]))
            a = next(a for a in out if solver.boolean_value(mdl.x[q][a]))
            path.append(a)
            state = int(lat.arc_head[a])
        arcs.append(np.array(path, dtype=np.int64))
    return scenario.plan_of(arcs)


def solve_exact(problem: RoadSearchProblem, *, time_limit_s: float = 10.0, seed: int = 0,
                initial: RoadPlan | None = None) -> Result[RoadPlan]:
    """Solve the maximum coverage program (module docstring) within ``time_limit_s``.

    ``initial`` (e.g. the beam's plan) is hinted and the answer is never worse than it.
    """
    deadline = Deadline(time_limit_s)
    sc = problem.scenario
    ub = sc.upper_bound()
    mdl = build_model(sc)
    start_value = -math.inf
    if initial is not None:
        _hint(mdl, sc, initial)
        start_value = sc.score(initial)
    stats = {"arcs": float(sum(len(x) for x in mdl.x)), "groups": float(sc.n_groups),
             "nested": float(len(mdl.nested))}
    if deadline.remaining() < 1e-3:
        return _answer(initial, start_value, ub, deadline, "exact: no time left to solve", stats)
    solver = cp_model.CpSolver()
    solver.parameters.max_time_in_seconds = max(1e-3, deadline.remaining())
    solver.parameters.num_workers = 1
    solver.parameters.linearization_level = 2
    solver.parameters.random_seed = seed
    solver.parameters.catch_sigint_signal = False  # Ctrl-C is core.interrupt's
    with watch(solver.stop_search):  # a stop request ends the search, keeping what it found
        native = solver.solve(mdl.model)
    name = solver.status_name(native)
    if native in (cp_model.INFEASIBLE, cp_model.MODEL_INVALID):
        return Result(Status.ERROR, None, None, deadline.elapsed(), "exact", None,
                      message=f"exact: CP-SAT {name} (a modelling error)", stats=stats)
    bound = ub
    if native in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        bound = min(ub, solver.best_objective_bound / mdl.scale)
        plan = _read(mdl, sc, solver)
        value = sc.score(plan)
        if value >= start_value or initial is None:
            return _answer(plan, value, bound, deadline, f"exact: CP-SAT {name}", stats)
    return _answer(initial, start_value, bound, deadline, f"exact: CP-SAT {name}", stats)


def _answer(plan: RoadPlan | None, value: float, bound: float, deadline: Deadline, note: str,
            stats: dict[str, float]) -> Result[RoadPlan]:
    if plan is None:
        return Result(Status.NO_SOLUTION, None, bound, deadline.elapsed(), "exact", None,
                      message=note, stats=stats)
    bound = max(bound, value)
    optimal = meets_bound(value, bound, REL_TOL)
    return Result(Status.OPTIMAL if optimal else Status.FEASIBLE, value, bound,
                  deadline.elapsed(), "exact", plan, message=note, stats=stats)
