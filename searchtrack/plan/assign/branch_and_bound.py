"""Exact END assignment by depth-first branch and bound with submodular bounds.

A node fixes the actions of some UAVs (selection ``S``). Because END is monotone submodular,
``f(OPT | S) ≤ f(S) + Σ_{r free} max_a Δ((r, a) | S)``, so a node whose bound does not beat the
incumbent is pruned. The next UAV to branch on is the free one with the largest best gain, its
actions tried in decreasing gain. The data are those of the integer program after its exact
reductions (dominated actions, unseen particles and duplicate particles removed), so every
node costs one small matrix–vector product per free UAV. The incumbent starts from lazy greedy.
"""

from __future__ import annotations

import math

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result, Status
from searchtrack.core.types import BoolArray, FloatArray
from searchtrack.plan.assign.exact import formulate
from searchtrack.plan.assign.greedy import solve_lazy_greedy
from searchtrack.plan.assign.objectives import ExpectedDetectionsFunction, coverage_only
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem

_TOL = 1e-9


class _Search:
    """State of one branch-and-bound run over the reduced data."""

    def __init__(self, problem: AssignmentProblem, deadline: Deadline) -> None:
        form = formulate(problem)
        self.form = form
        self.weights = form.weights
        self.miss = [np.exp(-form.ell[:, lo:hi]).T for lo, hi in
                     zip(form.offsets[:-1], form.offsets[1:], strict=True)]  # (A_r, n)
        self.deadline = deadline
        self.robots = problem.robots
        self.conflict: dict[tuple[int, int], BoolArray] = {}
        for (r, s), bad in problem.conflicts.items():
            self.conflict[(r, s)] = bad[np.ix_(form.kept[r], form.kept[s])]
        self.best_value = -math.inf
        self.best: list[int] | None = None
        self.nodes = 0
        self.complete = True

    def allowed(self, chosen: dict[int, int], r: int) -> BoolArray:
        ok = np.ones(self.miss[r].shape[0], dtype=bool)
        for s, a in chosen.items():
            if (s, r) in self.conflict:
                ok &= ~self.conflict[(s, r)][a]
            elif (r, s) in self.conflict:
                ok &= ~self.conflict[(r, s)][:, a]
        return ok

    def run(self, chosen: dict[int, int], m: FloatArray, value: float) -> None:
        self.nodes += 1
        if self.nodes % 64 == 0 and self.deadline.expired():
            self.complete = False
            return
        if len(chosen) == self.robots:
            if value > self.best_value + _TOL:
                self.best_value = value
                self.best = [chosen[r] for r in range(self.robots)]
            return
        wm = self.weights * m
        total = float(wm.sum())
        gains: dict[int, FloatArray] = {}
        for r in range(self.robots):
            if r not in chosen:
                g = np.maximum(total - self.miss[r] @ wm, 0.0)
                gains[r] = np.where(self.allowed(chosen, r), g, -np.inf)
        tops = {r: float(np.max(g)) for r, g in gains.items()}
        if any(t == -math.inf for t in tops.values()):
            return  # some free UAV has no collision-free action left
        if value + sum(tops.values()) <= self.best_value + _TOL:
            return
        r = max(tops, key=lambda s: (tops[s], -s))
        rest = sum(tops.values()) - tops[r]
        order = np.argsort(-gains[r], kind="stable")
        for a in order:
            step = float(gains[r][a])
            if step == -math.inf or value + step + rest <= self.best_value + _TOL:
                break
            chosen[r] = int(a)
            self.run(chosen, m * self.miss[r][a], value + step)
            del chosen[r]
            if not self.complete:
                return


def solve_branch_and_bound(problem: AssignmentProblem, *, time_limit_s: float = 10.0,
                           seed: int = 0) -> Result[Assignment]:
    """Solve the END assignment exactly by branch and bound (module docstring).

    OPTIMAL when the search completes; FEASIBLE with the root bound when the limit stops it.
    ``seed`` is unused (deterministic).
    """
    reason = coverage_only(problem)
    if reason is not None:
        raise InvalidInputError("objective", problem.objective, f"branch and bound {reason}")
    deadline = Deadline(time_limit_s)
    greedy = solve_lazy_greedy(problem, time_limit_s=time_limit_s, seed=seed)
    search = _Search(problem, deadline)
    end = ExpectedDetectionsFunction(problem)
    if greedy.plan is not None:
        search.best_value = end.value(greedy.plan.selection) - 2 * _TOL
        search.best = [int(search.form.column_of[r][a]) for r, a in greedy.plan.selection]
    search.run({}, np.ones(search.weights.shape[0]), 0.0)
    stats = {"nodes": float(search.nodes), "columns": float(search.form.ell.shape[1])}
    if search.best is None:
        status = Status.INFEASIBLE if search.complete else Status.NO_SOLUTION
        return Result(status, None, None, deadline.elapsed(), "exact_bnb", None,
                      message="exact_bnb: " + ("every joint action collides" if search.complete
                                               else "time limit before any plan"), stats=stats)
    actions = [int(search.form.kept[r][c]) for r, c in enumerate(search.best)]
    value = end.value(tuple(enumerate(actions)))
    bound = value if search.complete else greedy.bound
    return Result(Status.OPTIMAL if search.complete else Status.FEASIBLE, value, bound,
                  deadline.elapsed(), "exact_bnb", Assignment.of(problem, actions),
                  message=f"exact_bnb: {search.nodes} nodes, "
                  f"{'complete' if search.complete else 'stopped at the limit'}", stats=stats)
