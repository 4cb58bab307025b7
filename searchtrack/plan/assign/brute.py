"""Exact assignment by enumeration, for tiny instances and for checking the other solvers."""

from __future__ import annotations

import itertools
import math

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem

#: Largest number of joint actions ``Π_r |Q^r|`` brute force accepts.
MAX_JOINT = 2_000_000


def joint_size(problem: AssignmentProblem) -> int:
    """``Π_r |Q^r|``, the number of joint actions."""
    return math.prod(problem.n_actions(r) for r in range(problem.robots))


def supports_brute_force(problem: AssignmentProblem) -> str | None:
    """``None`` if enumeration is small enough, else the reason."""
    size = joint_size(problem)
    return None if size <= MAX_JOINT else f"{size} joint actions exceed {MAX_JOINT}"


def solve_brute_force(problem: AssignmentProblem, *, time_limit_s: float = 10.0,
                      seed: int = 0) -> Result[Assignment]:
    """Enumerate every collision-free joint action of the first ``R − 1`` UAVs and take the best
    action of the last one by its vector of marginal gains. OPTIMAL when the enumeration ends in
    time on exact values, FEASIBLE (best so far, no bound) when the limit stops it or the values
    are estimates (MI above ``exact_max`` measurements). ``seed`` is unused."""
    del seed
    deadline = Deadline(time_limit_s)
    objective = problem.objective.evaluator(problem)
    last = problem.robots - 1
    best_value = -math.inf
    best: tuple[int, ...] | None = None
    done = True
    ranges = [range(problem.n_actions(r)) for r in range(last)]
    for count, head in enumerate(itertools.product(*ranges)):
        if count % 256 == 0 and deadline.expired():
            done = False
            break
        selection = tuple(enumerate(head))
        if any(not problem.compatible(selection[:r], r)[a] for r, a in selection):
            continue
        ok = problem.compatible(selection, last)
        if not np.any(ok):
            continue
        gains = np.where(ok, objective.gains(selection, last), -np.inf)
        a = int(np.argmax(gains))
        value = objective.value(selection) + float(gains[a])
        if value > best_value + 1e-12:
            best_value, best = value, (*head, a)
    if best is None:
        status = Status.INFEASIBLE if done else Status.NO_SOLUTION
        return Result(status, None, None, deadline.elapsed(), "brute_force", None,
                      message="brute_force: " + ("every joint action collides" if done
                                                 else "time limit before any plan"))
    value = objective.value(tuple(enumerate(best)))
    message = f"brute_force: {'enumerated' if done else 'stopped at the limit'}"
    estimate = problem.objective.estimated(problem)
    if estimate is not None:
        # The best estimated value proves nothing about the true objective.
        done = False
        message += f"; {estimate}"
    return Result(Status.OPTIMAL if done else Status.FEASIBLE, value, value if done else None,
                  deadline.elapsed(), "brute_force", Assignment.of(problem, best),
                  message=message)
