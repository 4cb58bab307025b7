"""Greedy assignment (paper 003 Algorithm 1) and its lazy variant (Minoux's priority queue).

Guarantee (003 Theorem 1): for a monotone submodular ``f`` with ``f(∅) = 0`` under the partition
matroid "at most one action per UAV", the greedy selection ``G`` satisfies ``f(G) ≥ ½ f(OPT)``.
Proof sketch: at step ``i`` UAV ``r_i``'s optimal action ``o_{r_i}`` was still available, so
``Δ(g_i | G_{i−1}) ≥ Δ(o_{r_i} | G_{i−1}) ≥ Δ(o_{r_i} | G)``; hence
``f(OPT) ≤ f(G) + Σ_r Δ(o_r | G) ≤ 2 f(G)``. Collision pruning conditional on earlier picks is not a
matroid constraint, so with conflicts the ½ factor is not guaranteed; the reported data-dependent
bound ``f(G) + Σ_r max_a Δ((r, a) | G)`` (END only) holds either way.
"""

from __future__ import annotations

import heapq
import logging

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.plan.assign.objectives import Selection, SetFunction
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem

log = logging.getLogger("searchtrack.plan.assign")

_TOL = 1e-9


def online_bound(problem: AssignmentProblem, objective: SetFunction, selection: Selection,
                 value: float) -> float | None:
    """A proven upper bound on the optimum from the greedy answer (``None`` if none applies).

    Coverage (END): ``f(G) + Σ_r max_a Δ((r, a) | G)`` (monotone submodular); otherwise (MI),
    without conflicts, ``2 f(G)`` (the exact MI is cheap enough only for the ½ bound).
    """
    if problem.objective.coverage:
        extra = sum(float(np.max(objective.gains(selection, r))) for r in range(problem.robots))
        return value + extra
    return 2.0 * value if not problem.conflicts else None


def _result(problem: AssignmentProblem, objective: SetFunction, chosen: dict[int, int],
            deadline: Deadline, backend: str, evaluations: int) -> Result[Assignment]:
    if len(chosen) < problem.robots:
        missing = sorted(set(range(problem.robots)) - set(chosen))
        why = "time limit" if deadline.expired() else f"no collision-free action for UAVs {missing}"
        return Result(Status.NO_SOLUTION, None, None, deadline.elapsed(), backend, None,
                      message=f"{backend}: {why}")
    actions = [chosen[r] for r in range(problem.robots)]
    selection = tuple(enumerate(actions))
    value = objective.value(selection)
    bound = online_bound(problem, objective, selection, value)
    status = Status.OPTIMAL if bound is not None and bound <= value + _TOL else Status.FEASIBLE
    return Result(status, value, bound, deadline.elapsed(), backend,
                  Assignment.of(problem, actions),
                  message=f"{backend}: {problem.objective.name} {value:.6g}",
                  stats={"evaluations": float(evaluations)})


def solve_greedy(problem: AssignmentProblem, *, time_limit_s: float = 10.0,
                 seed: int = 0) -> Result[Assignment]:
    """Algorithm 1 of paper 003: repeatedly assign the best (UAV, action) pair over all
    unassigned UAVs, conditioned on the actions already assigned; actions that collide with an
    assigned one are discarded. Ties go to the lowest UAV, then the lowest action index.
    ``seed`` is unused (deterministic). ``f(G) ≥ ½ OPT`` for a partition matroid."""
    del seed
    deadline = Deadline(time_limit_s)
    objective = problem.objective.evaluator(problem)
    chosen: dict[int, int] = {}
    evaluations = 0
    while len(chosen) < problem.robots and not deadline.expired():
        selection = tuple(chosen.items())
        best: tuple[float, int, int] | None = None
        stuck = False
        for r in range(problem.robots):
            if r in chosen:
                continue
            gains = objective.gains(selection, r)
            evaluations += gains.size
            ok = problem.compatible(selection, r)
            if not np.any(ok):
                stuck = True
                break
            masked = np.where(ok, gains, -np.inf)
            a = int(np.argmax(masked))
            if best is None or masked[a] > best[0] + _TOL:
                best = (float(masked[a]), r, a)
        if stuck or best is None:
            break
        chosen[best[1]] = best[2]
    return _result(problem, objective, chosen, deadline, "greedy", evaluations)


def solve_lazy_greedy(problem: AssignmentProblem, *, time_limit_s: float = 10.0,
                      seed: int = 0) -> Result[Assignment]:
    """Lazy greedy: the same picks as :func:`solve_greedy` (up to ties) with stale gains in a
    priority queue, re-evaluated only when they reach the top (valid by submodularity).
    ``seed`` is unused (deterministic)."""
    del seed
    deadline = Deadline(time_limit_s)
    objective = problem.objective.evaluator(problem)
    heap: list[tuple[float, int, int, int]] = []  # (−gain, robot, action, round evaluated)
    for r in range(problem.robots):
        for a, g in enumerate(objective.gains((), r)):
            heap.append((-float(g), r, a, 0))
    evaluations = len(heap)
    heapq.heapify(heap)
    chosen: dict[int, int] = {}
    while heap and len(chosen) < problem.robots and not deadline.expired():
        _neg, r, a, stamp = heapq.heappop(heap)
        if r in chosen:
            continue
        selection = tuple(chosen.items())
        if not problem.compatible(selection, r)[a]:
            continue
        if stamp == len(chosen):
            chosen[r] = a
            continue
        g = objective.gain(selection, r, a)
        evaluations += 1
        heapq.heappush(heap, (-g, r, a, len(chosen)))
    return _result(problem, objective, chosen, deadline, "lazy_greedy", evaluations)
