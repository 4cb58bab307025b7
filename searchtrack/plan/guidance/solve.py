"""Solve one step of guidance by backend name, like every other solver family of searchtrack.

    problem = GuidanceProblem(view, StrategyConfig(), tracker_diffusion)
    result = solve(problem, backend="search_and_reacquire", time_limit_s=0.03, seed=seed)
    uavs = step_force(uavs, result.plan.force, dt_s, limits,
                      turn_back=result.plan.turn_back("turn_back"))  # or "thesis": (5.3)
    problem = problem.following(next_view, result.plan)    # carries the routes being flown

The backends are the Ch. 5 strategies (:mod:`searchtrack.plan.guidance.strategies`) and this
library's route strategies, whose searching UAVs fly OPTW routes over the search field
(:mod:`searchtrack.plan.guidance.route_strategies`).
"""

from __future__ import annotations

from searchtrack.core.registry import Backend, Registry
from searchtrack.core.result import Result
from searchtrack.plan.guidance.problem import GuidanceProblem
from searchtrack.plan.guidance.route_strategies import (
    solve_route_loiter,
    solve_route_partition_loiter,
    solve_route_partition_search,
    solve_route_search,
    solve_route_search_and_loiter,
    solve_route_search_and_reacquire,
)
from searchtrack.plan.guidance.strategies import (
    solve_loiter,
    solve_search,
    solve_search_and_loiter,
    solve_search_and_reacquire,
)
from searchtrack.plan.guidance.validate import answer_problems
from searchtrack.plan.guidance.view import Guidance

#: The guidance strategies by name.
BACKENDS: Registry[GuidanceProblem, Guidance] = Registry("guidance", validator=answer_problems)
BACKENDS.register(Backend("search", solve_search, False,
                          "every UAV searches: ∇R + ∇P + ∇Q (5.12)"))
BACKENDS.register(Backend("loiter", solve_loiter, False,
                          "paired UAVs loiter over their tracker's peak, the rest search (5.15)"))
BACKENDS.register(Backend("search_and_loiter", solve_search_and_loiter, False,
                          "paired UAVs loiter while their tracker's peak is ≤ ϱ (5.16)"))
BACKENDS.register(Backend("search_and_reacquire", solve_search_and_reacquire, False,
                          "as search-and-loiter, but a fading tracker's UAV flies an OPTW route "
                          "over its likely nodes (5.33)"))
BACKENDS.register(Backend("route_search", solve_route_search, False,
                          "every UAV flies OPTW search routes over the search field's mass"))
BACKENDS.register(Backend("route_loiter", solve_route_loiter, False,
                          "paired UAVs loiter (5.15), the rest fly OPTW search routes"))
BACKENDS.register(Backend("route_search_and_loiter", solve_route_search_and_loiter, False,
                          "paired UAVs loiter while their peak is ≤ ϱ (5.16), searching UAVs fly "
                          "OPTW search routes"))
BACKENDS.register(Backend("route_search_and_reacquire", solve_route_search_and_reacquire, False,
                          "as search-and-reacquire (5.33), searching UAVs flying OPTW search "
                          "routes"))
BACKENDS.register(Backend("route_partition_search", solve_route_partition_search, False,
                          "every UAV flies OPTW search routes over its part of a balanced "
                          "partition of the search field's mass, prizes discounted by arrival"))
BACKENDS.register(Backend("route_partition_loiter", solve_route_partition_loiter, False,
                          "paired UAVs loiter (5.15), the rest fly OPTW search routes over their "
                          "part of a balanced partition of the mass, prizes discounted by "
                          "arrival"))


def solve(problem: GuidanceProblem, *, backend: str = "search_and_reacquire",
          time_limit_s: float = 0.03, seed: int = 0) -> Result[Guidance]:
    """The forces, modes and routes of one step with the named guidance backend.

    Parameters
    ----------
    problem
        The step: view, configuration, tracker predictor and the routes being flown.
    backend
        A name of :data:`BACKENDS`: ``"search"``, ``"loiter"``, ``"search_and_loiter"``,
        ``"search_and_reacquire"`` or a route strategy (``"route_search"``, ``"route_loiter"``,
        ``"route_search_and_loiter"``, ``"route_search_and_reacquire"``, and their partitioned
        variants ``"route_partition_search"``, ``"route_partition_loiter"``).
    time_limit_s
        The step's planning budget: the OPTW solves of the step (reacquisition, search) share
        it.
    seed
        Seeds the gradient tie-break and the OPTW solves (a mission draws one per step).

    Returns
    -------
    Result
        ``FEASIBLE`` with the :class:`~searchtrack.plan.guidance.view.Guidance` as plan; the
        objective is the tracker probability the plan sets out to cover (see
        :mod:`~searchtrack.plan.guidance.strategies`), ``bound`` ``None``.

    Raises
    ------
    InvalidInputError
        Unknown backend, a bad time limit or seed.
    """
    return BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)
