"""Solve a search step by backend name: ``receding`` enumerates every lattice sequence of the
horizon (exact over the lattice), ``lawnmower`` follows the 3-D coverage pattern, ``auto`` is
``receding``."""

from __future__ import annotations

import dataclasses
import math

from searchtrack.core.registry import Backend, Registry
from searchtrack.core.result import Result
from searchtrack.plan.search.lawnmower import lawnmower_supports, solve_lawnmower
from searchtrack.plan.search.problem import SearchPlan, SearchProblem
from searchtrack.plan.search.receding import solve_receding
from searchtrack.plan.search.validate import answer_problems


def _auto(problem: SearchProblem, *, time_limit_s: float, seed: int) -> Result[SearchPlan]:
    result = solve_receding(problem, time_limit_s=time_limit_s, seed=seed)
    return dataclasses.replace(result, message=f"auto: {result.message}")


BACKENDS: Registry[SearchProblem, SearchPlan] = Registry("search", validator=answer_problems)
BACKENDS.register(Backend("auto", _auto, True, "the receding-horizon planner (receding)"))
BACKENDS.register(Backend("receding", solve_receding, True,
                          "004 eqs. 7-8: score every lattice sequence of the horizon, best first"))
BACKENDS.register(Backend("lawnmower", solve_lawnmower, False,
                          "004's 3-D lawnmower: the next waypoints of the coverage pattern",
                          supports=lawnmower_supports))


def solve(problem: SearchProblem, *, backend: str = "receding", time_limit_s: float = math.inf,
          seed: int = 0) -> Result[SearchPlan]:
    """Plan the next positions of the searching UAV with the named backend.

    The default limit is none (``inf``), so closed-loop runs are reproducible; a finite
    ``time_limit_s`` may stop the enumeration early (``FEASIBLE``).

    Raises
    ------
    InvalidInputError
        Unknown backend, a backend that cannot take the problem, a bad limit or seed.
    """
    return BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)
