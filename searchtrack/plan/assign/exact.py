"""Exact END assignment: an integer program with an outer approximation of ``1 − e^{−L}``.

END (paper 003 eq. 13) as an integer program. With
``ℓ_{j,(r,a)} = −Σ_t log(1 − p_d(x_j | q_{r,a,t}))`` (``p_d`` capped below 1) the miss product of
particle ``j`` is ``e^{−L_j}``, ``L_j = Σ ℓ_{j,(r,a)} x_{r,a}``, and
END ``= Σ_j w_j (1 − e^{−L_j})``. The program::

    max Σ_j w_j u_j
    s.t. Σ_a x_{r,a} = 1                       (one action per UAV: a partition matroid)
         L_j = Σ_{r,a} ℓ_{j,(r,a)} x_{r,a}
         u_j ≤ 1 − e^{−b} + e^{−b} (L_j − b)     (tangents of the concave 1 − e^{−L} at b ∈ B_j)
         u_j ≤ Σ_{r,a} (1 − e^{−ℓ_{j,(r,a)}}) x_{r,a}  (subadditivity of the concave f, f(0) = 0)
         u_j ≤ 1,  x_{r,a} + x_{s,b} ≤ 1 for colliding action pairs,  x binary

is an outer approximation: its optimum is an upper bound on the true optimum. The plan is then
evaluated with the true END; tangents at the plan's own ``L_j`` are added and the program re-solved
(Kelley's cutting planes) until the bound meets the plan's true END (status OPTIMAL), or the time
runs out (FEASIBLE with the best plan and the tightest bound). Particles no action can see are
dropped, particles with identical ``ℓ`` rows are merged, and actions dominated by another
collision-free action of the same UAV (covering every particle at least as well) are dropped.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.interrupt import watch
from searchtrack.core.result import Result, Status
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.plan.assign.objectives import ExpectedDetectionsFunction, coverage_only
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem

log = logging.getLogger("searchtrack.plan.assign")

MipSolver = Literal["scip", "cpsat"]
_REL_TOL = 1e-6


@dataclass(frozen=True)
class Formulation:
    """The reduced data of the program: ``ell`` ``(n, K)``, merged weights ``(n,)``, the column
    offset of each UAV's kept actions, the colliding column pairs, the original action index of
    each kept column (``kept[r]``) and the column standing in for every action (``column_of[r]``,
    the action itself or one that dominates it)."""

    ell: FloatArray
    weights: FloatArray
    offsets: tuple[int, ...]
    conflicts: tuple[tuple[int, int], ...]
    kept: tuple[IntArray, ...]
    column_of: tuple[IntArray, ...]


def undominated(ell: FloatArray, free: BoolArray) -> tuple[IntArray, IntArray]:
    """Columns of one UAV's ``(N, A)`` ``ℓ`` that no other column dominates, and for every
    column the kept column that stands in for it.

    Column ``a`` is dominated by ``b`` when ``ℓ_b ≥ ℓ_a`` for every particle (``b`` misses no
    particle more often) and ``b`` collides with nothing (``free[b]``); for equal columns the
    lowest index is kept. Swapping ``a`` for ``b`` never lowers END nor breaks a plan, so the
    optimum over the kept columns is the optimum over all.
    """
    a_count = ell.shape[1]
    dominator = np.arange(a_count)
    for a in range(a_count):
        ge = np.all(ell >= ell[:, a:a + 1], axis=0) & free
        ge[a] = False
        gt = ge & (np.any(ell > ell[:, a:a + 1], axis=0) | (np.arange(a_count) < a))
        if np.any(gt):
            dominator[a] = int(np.flatnonzero(gt)[0])
    for _ in range(a_count):  # follow chains to a kept column
        nxt = dominator[dominator]
        if np.array_equal(nxt, dominator):
            break
        dominator = nxt
    kept = np.flatnonzero(dominator == np.arange(a_count))
    position = np.full(a_count, -1)
    position[kept] = np.arange(kept.size)
    return kept, position[dominator]


def formulate(problem: AssignmentProblem, *, reduce: bool = True) -> Formulation:
    """Stack ``ℓ`` over the undominated actions (all of them if ``reduce`` is False), drop
    unseen particles and merge duplicate rows."""
    blocks, kept_all, column_of = [], [], []
    for r, m in enumerate(problem.log_miss):
        free = np.ones(m.shape[0], dtype=bool)
        for (s, u), bad in problem.conflicts.items():
            if s == r:
                free &= ~np.any(bad, axis=1)
            elif u == r:
                free &= ~np.any(bad, axis=0)
        if reduce:
            seen = np.any(m > 0.0, axis=0)
            kept, col = undominated(m[:, seen].T, free)
        else:
            kept, col = np.arange(m.shape[0]), np.arange(m.shape[0])
        blocks.append(m[kept].T)
        kept_all.append(kept)
        column_of.append(col)
    ell = np.concatenate(blocks, axis=1)  # (N, K)
    keep = (problem.weights > 0.0) & np.any(ell > 0.0, axis=1)
    ell, w = ell[keep], problem.weights[keep]
    if ell.shape[0] > 0:
        rows, inverse = np.unique(np.round(ell, 12), axis=0, return_inverse=True)
        w = np.bincount(inverse.reshape(-1), weights=w, minlength=rows.shape[0])
        ell = rows
    offsets = tuple(int(x) for x in np.cumsum([0] + [k.size for k in kept_all]))
    pairs: list[tuple[int, int]] = []
    for (r, s), bad in problem.conflicts.items():
        sub_bad = bad[np.ix_(kept_all[r], kept_all[s])]
        for a, b in zip(*np.nonzero(sub_bad), strict=True):
            pairs.append((offsets[r] + int(a), offsets[s] + int(b)))
    return Formulation(ell, w, offsets, tuple(pairs), tuple(kept_all), tuple(column_of))


def initial_breakpoints(form: Formulation, pieces: int) -> list[list[float]]:
    """Per particle, ``pieces`` tangent points with ``1 − e^{−b}`` evenly spaced up to the most
    coverage any joint action can give (``b = 0`` first: the cut ``u ≤ L``)."""
    lmax = np.zeros(form.ell.shape[0])
    for lo, hi in zip(form.offsets[:-1], form.offsets[1:], strict=True):
        lmax += np.max(form.ell[:, lo:hi], axis=1)
    out = []
    for top in lmax:
        fmax = 1.0 - math.exp(-float(top))
        ys = np.linspace(0.0, fmax, pieces, endpoint=False) if pieces > 0 else np.zeros(1)
        out.append(sorted({float(-math.log1p(-y)) for y in ys}))
    return out


def _solve_scip(form: Formulation, cuts: list[list[float]], start: list[int] | None,
                deadline: Deadline) -> tuple[str, list[int] | None, float | None]:
    from ortools.linear_solver import pywraplp

    solver = pywraplp.Solver.CreateSolver("SCIP")
    if solver is None:
        raise RuntimeError("OR-Tools was built without SCIP")
    k = form.ell.shape[1]
    x = [solver.BoolVar(f"x{i}") for i in range(k)]
    for lo, hi in zip(form.offsets[:-1], form.offsets[1:], strict=True):
        solver.Add(sum(x[lo:hi]) == 1)
    for i, j in form.conflicts:
        solver.Add(x[i] + x[j] <= 1)
    objective = solver.Objective()
    for p in range(form.ell.shape[0]):
        if p % 256 == 0 and deadline.expired():
            return "NOT_SOLVED", None, None
        u = solver.NumVar(0.0, 1.0, f"u{p}")
        sub_add = solver.Constraint(-solver.infinity(), 0.0)
        sub_add.SetCoefficient(u, 1.0)
        for col in np.flatnonzero(form.ell[p]):
            sub_add.SetCoefficient(x[int(col)], -float(-math.expm1(-form.ell[p, col])))
        objective.SetCoefficient(u, float(form.weights[p]))
        tangents = [b for b in cuts[p] if b > 0.0]  # b = 0 (u ≤ L) is implied by sub_add
        if not tangents:
            continue
        cover = solver.NumVar(0.0, solver.infinity(), f"L{p}")
        row = solver.Constraint(0.0, 0.0)
        row.SetCoefficient(cover, -1.0)
        for col in np.flatnonzero(form.ell[p]):
            row.SetCoefficient(x[int(col)], float(form.ell[p, col]))
        for b in tangents:
            e = math.exp(-b)
            cut = solver.Constraint(-solver.infinity(), 1.0 - e - e * b)
            cut.SetCoefficient(u, 1.0)
            cut.SetCoefficient(cover, -e)
    objective.SetMaximization()
    if start is not None:
        hint = [1.0 if i in set(start) else 0.0 for i in range(k)]
        solver.SetHint(x, hint)
    solver.SetNumThreads(1)
    if deadline.expired():
        return "NOT_SOLVED", None, None
    solver.SetTimeLimit(max(1, int(deadline.remaining() * 1000)))
    solver.SetSolverSpecificParametersAsString("misc/catchctrlc = FALSE\n")
    with watch(solver.InterruptSolve):
        native = solver.Solve()
    names = {pywraplp.Solver.OPTIMAL: "OPTIMAL", pywraplp.Solver.FEASIBLE: "FEASIBLE",
             pywraplp.Solver.INFEASIBLE: "INFEASIBLE", pywraplp.Solver.NOT_SOLVED: "NOT_SOLVED"}
    name = names.get(native, "ERROR")
    if name not in ("OPTIMAL", "FEASIBLE"):
        return name, None, None
    chosen = [i for i in range(k) if x[i].solution_value() > 0.5]
    bound = objective.Value() if name == "OPTIMAL" else objective.BestBound()
    return name, chosen, float(bound)


_L_SCALE = 1000.0
_U_SCALE = 10000
_W_SCALE = 1e6


def _solve_cpsat(form: Formulation, cuts: list[list[float]], start: list[int] | None,
                 deadline: Deadline) -> tuple[str, list[int] | None, float | None]:
    """CP-SAT on the same program scaled to integers, every rounding made in the direction that
    keeps the bound valid (coverage and slopes rounded up, ``u`` allowed one step more)."""
    from ortools.sat.python import cp_model

    model = cp_model.CpModel()
    k = form.ell.shape[1]
    x = [model.new_bool_var(f"x{i}") for i in range(k)]
    for lo, hi in zip(form.offsets[:-1], form.offsets[1:], strict=True):
        model.add_exactly_one(x[lo:hi])
    for i, j in form.conflicts:
        model.add_bool_or([x[i].Not(), x[j].Not()])
    ell_int = np.ceil(form.ell * _L_SCALE).astype(np.int64)
    terms = []
    for p in range(form.ell.shape[0]):
        if p % 256 == 0 and deadline.expired():
            return "NOT_SOLVED", None, None
        nz = np.flatnonzero(ell_int[p])
        u = model.new_int_var(0, _U_SCALE, f"u{p}")
        cover_expr = sum(int(ell_int[p, i]) * x[int(i)] for i in nz)
        model.add(u <= 1 + sum(math.ceil(-math.expm1(-form.ell[p, i]) * _U_SCALE) * x[int(i)]
                               for i in nz))
        for b in cuts[p]:
            e = math.exp(-b)
            rhs0 = math.ceil((1.0 - e - e * b) * _U_SCALE * _L_SCALE) + int(_L_SCALE)
            slope = math.ceil(e * _U_SCALE)
            model.add(int(_L_SCALE) * u <= rhs0 + slope * cover_expr)
        terms.append(math.ceil(form.weights[p] * _W_SCALE) * u)
    model.maximize(sum(terms))
    if start is not None:
        for i in range(k):
            model.add_hint(x[i], i in set(start))
    solver = cp_model.CpSolver()
    if deadline.expired():
        return "NOT_SOLVED", None, None
    solver.parameters.max_time_in_seconds = max(1e-3, deadline.remaining())
    solver.parameters.num_workers = 1
    solver.parameters.catch_sigint_signal = False  # Ctrl-C is core.interrupt's
    with watch(solver.stop_search):
        native = solver.solve(model)
    name = {cp_model.OPTIMAL: "OPTIMAL", cp_model.FEASIBLE: "FEASIBLE",
            cp_model.INFEASIBLE: "INFEASIBLE", cp_model.UNKNOWN: "NOT_SOLVED"}.get(native, "ERROR")
    if name not in ("OPTIMAL", "FEASIBLE"):
        return name, None, None
    chosen = [i for i in range(k) if solver.boolean_value(x[i])]
    bound = solver.best_objective_bound / (_W_SCALE * _U_SCALE)
    return name, chosen, float(bound)


def solve_exact(problem: AssignmentProblem, *, time_limit_s: float = 10.0, seed: int = 0,
                solver: MipSolver = "scip", pieces: int = 1,
                initial: Assignment | None = None, reduce: bool = True) -> Result[Assignment]:
    """Solve the END assignment exactly by the outer-approximation program (module docstring).

    ``seed`` is unused (both solvers run single-threaded and deterministic).

    Parameters
    ----------
    solver
        ``"scip"`` (pywraplp, continuous ``u``) or ``"cpsat"`` (integer-scaled).
    pieces
        Tangents per particle in the first program (more are added at the plans found); 1 (only
        ``b = 0``, implied by the subadditivity cut) measured fastest.
    reduce
        Drop dominated actions first (exact; see :func:`undominated`).
    initial
        A plan to hint to the solver (e.g. greedy's); the answer is never worse than it.
    """
    del seed
    reason = coverage_only(problem)
    if reason is not None:
        raise InvalidInputError("objective", problem.objective, f"the integer program {reason}")
    if solver not in ("scip", "cpsat"):
        raise InvalidInputError("solver", solver, "must be 'scip' or 'cpsat'")
    if not isinstance(pieces, int) or pieces < 1:
        raise InvalidInputError("pieces", pieces, "must be a positive integer")
    deadline = Deadline(time_limit_s)
    backend = "exact" if solver == "scip" else "exact_cpsat"  # the registry's names
    end = ExpectedDetectionsFunction(problem)
    form = formulate(problem, reduce=reduce)
    cuts = initial_breakpoints(form, pieces)
    run = _solve_scip if solver == "scip" else _solve_cpsat
    start = None if initial is None else [form.offsets[r] + int(form.column_of[r][a])
                                          for r, a in initial.selection]
    best: tuple[float, list[int]] | None = None
    if initial is not None and all(problem.compatible(initial.selection[:r], r)[a]
                                   for r, a in initial.selection):
        best = (end.value(initial.selection), list(initial.actions))
    bound = math.inf
    rounds = 0
    native = "NOT_SOLVED"
    while not deadline.expired():
        rounds += 1
        native, cols, ip_bound = run(form, cuts, start, deadline)
        if cols is None or ip_bound is None:
            break
        if native == "OPTIMAL":
            bound = min(bound, ip_bound)
        actions = [int(form.kept[r][cols[r] - form.offsets[r]]) for r in range(problem.robots)]
        value = end.value(tuple(enumerate(actions)))
        if best is None or value > best[0]:
            best = (value, actions)
        start = [form.offsets[r] + int(form.column_of[r][a]) for r, a in enumerate(best[1])]
        if bound - best[0] <= _REL_TOL * max(1.0, best[0]):
            break
        if native != "OPTIMAL":
            bound = min(bound, ip_bound)
            break
        covers = np.zeros(form.ell.shape[0])
        for c in cols:
            covers += form.ell[:, c]
        added = 0
        for p, lp in enumerate(covers):
            if all(abs(lp - b) > 1e-9 for b in cuts[p]):
                cuts[p].append(float(lp))
                added += 1
        if added == 0:  # the program is exact at its own optimum: only rounding is left
            break
    stats = {"rounds": float(rounds), "particles": float(form.ell.shape[0]),
             "columns": float(form.ell.shape[1])}
    if best is None:
        status = Status.INFEASIBLE if native == "INFEASIBLE" else Status.NO_SOLUTION
        if native == "ERROR":
            status = Status.ERROR
        return Result(status, None, None, deadline.elapsed(), backend, None,
                      message=f"{backend}: {native}", stats=stats)
    value, actions = best
    finite = bound if math.isfinite(bound) else None
    closed = finite is not None and finite - value <= _REL_TOL * max(1.0, value)
    return Result(Status.OPTIMAL if closed else Status.FEASIBLE, value, finite,
                  deadline.elapsed(), backend, Assignment.of(problem, actions),
                  message=f"{backend}: {rounds} rounds, last {native}", stats=stats)
