"""Beam search over the look-ahead tree: the ``width`` best partial paths of each level are
expanded, the rest dropped (a fast stand-in for the exhaustive RHC on large maps; the paper
suggests such approximations for maps where ``d^L`` paths are too many, §4.2).

Several UAVs plan in turn, each given the particles the earlier ones see, then each re-plans
against all the others while that improves the objective (at most ``passes`` rounds). The answer
is ``FEASIBLE`` with the scenario's upper bound, or ``OPTIMAL`` when no path was dropped
(one UAV) or the plan meets that bound.
"""

from __future__ import annotations

from searchtrack.core import checks
from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.plan.road_search.exhaustive import sequential
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem, meets_bound

#: Paths kept per level by default.
DEFAULT_WIDTH = 32


def solve_beam(problem: RoadSearchProblem, *, time_limit_s: float = 10.0, seed: int = 0,
               width: int = DEFAULT_WIDTH, passes: int = 3) -> Result[RoadPlan]:
    """Beam search of ``width`` paths per level; ``seed`` is unused (deterministic).

    Raises
    ------
    InvalidInputError
        ``width`` or ``passes`` not a positive integer.
    """
    del seed
    checks.count("width", width, 1)
    checks.count("passes", passes, 1)
    deadline = Deadline(time_limit_s)
    sc = problem.scenario
    bound = sc.upper_bound()
    arcs, complete, pruned = sequential(sc, deadline, width, passes)
    if arcs is None:
        return Result(Status.NO_SOLUTION, None, bound, deadline.elapsed(), "beam", None,
                      message="beam: time limit before any complete path")
    plan = sc.plan_of(arcs)
    value = sc.score(plan)
    proven = problem.n_uavs == 1 and complete and not pruned
    optimal = proven or meets_bound(value, bound)
    note = f"beam: width {width}" + (", nothing pruned" if not pruned else "")
    return Result(Status.OPTIMAL if optimal else Status.FEASIBLE, value,
                  value if optimal else bound, deadline.elapsed(), "beam", plan, message=note)
