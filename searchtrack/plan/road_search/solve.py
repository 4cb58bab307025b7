"""Solve a road-search problem by backend name (Moore et al. 2021, §4.2 and §6).

``auto`` runs the beam search at once, then the CP-SAT program in the time left to improve or
prove it (:func:`~searchtrack.core.registry.heuristic_then_exact`); its result names the stage
whose plan it is. CP-SAT (OR-Tools) is imported only when ``exact`` or ``auto`` first needs it,
within the stage's time (:func:`~searchtrack.core.loading.loaded_within`): a first call whose
limit runs out while it loads answers without it (``auto``: the beam's answer).

The time limit covers the fixed-draw scenario every backend scores
(:mod:`searchtrack.plan.road_search.scenario`): :func:`solve` builds it first, within the limit
(a build that outlasts it answers ``NO_SOLUTION``, ``INTERRUPTED`` on a stop request), the
backend gets the time left, and the answer's runtime counts the build.
"""

from __future__ import annotations

import dataclasses

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.loading import loaded_within, still_loading
from searchtrack.core.registry import Backend, Registry, check_seed, heuristic_then_exact
from searchtrack.core.result import Result, Status, interrupted
from searchtrack.plan.road_search.baselines import solve_ideal, solve_random, supports_ideal
from searchtrack.plan.road_search.beam import solve_beam
from searchtrack.plan.road_search.exhaustive import solve_exhaustive, supports_exhaustive
from searchtrack.plan.road_search.greedy import solve_greedy
from searchtrack.plan.road_search.problem import RoadPlan, RoadSearchProblem
from searchtrack.plan.road_search.validator import answer_problems

_EXACT = "searchtrack.plan.road_search.exact"


def _exact(problem: RoadSearchProblem, *, time_limit_s: float, seed: int,
           initial: RoadPlan | None = None) -> Result[RoadPlan]:
    deadline = Deadline(time_limit_s)
    if not loaded_within(_EXACT, deadline):
        return still_loading("exact", "OR-Tools", deadline)
    from searchtrack.plan.road_search.exact import solve_exact

    return solve_exact(problem, time_limit_s=max(1e-3, deadline.remaining()), seed=seed,
                       initial=initial)


def _prove(problem: RoadSearchProblem, first: Result[RoadPlan], limit_s: float,
           seed: int) -> Result[RoadPlan]:
    return _exact(problem, time_limit_s=limit_s, seed=seed, initial=first.plan)


def _auto(problem: RoadSearchProblem, *, time_limit_s: float, seed: int) -> Result[RoadPlan]:
    return heuristic_then_exact(problem, solve_beam, _prove, time_limit_s=time_limit_s,
                                seed=seed, heuristic_limit_s=time_limit_s, tol=1e-7)


BACKENDS: Registry[RoadSearchProblem, RoadPlan] = Registry("road search",
                                                         validator=answer_problems)
BACKENDS.register(Backend("auto", _auto, True,
                          "beam at once, then CP-SAT in the time left to improve or prove it"))
BACKENDS.register(Backend("exhaustive", solve_exhaustive, True,
                          "the paper's RHC: every path (every joint choice when small)",
                          supports=supports_exhaustive))
BACKENDS.register(Backend("beam", solve_beam, False,
                          "beam search of the look-ahead tree, UAVs in turn"))
BACKENDS.register(Backend("exact", _exact, True,
                          "maximum coverage on the time-expanded graph, CP-SAT"))
BACKENDS.register(Backend("greedy", solve_greedy, False,
                          "best weighted edge value (Eq. 21) at each node"))
BACKENDS.register(Backend("random", solve_random, False,
                          "uniform choice of the next edge (baseline)"))
BACKENDS.register(Backend("ideal", solve_ideal, False,
                          "shortest path to the true targets (baseline)", supports=supports_ideal))


def solve(problem: RoadSearchProblem, *, backend: str = "auto", time_limit_s: float = 1.0,
          seed: int = 0) -> Result[RoadPlan]:
    """Plan every UAV's look-ahead path with the named backend within ``time_limit_s``, the
    scenario's build included (module docstring).

    Raises
    ------
    InvalidInputError
        Unknown backend, a backend that cannot take the problem, a bad limit or seed.
    """
    check_time_limit(time_limit_s)
    check_seed(seed)
    BACKENDS.get(backend)
    deadline = Deadline(time_limit_s)
    if not problem.scenario_within(deadline):
        return interrupted(Result(
            Status.NO_SOLUTION, None, None, deadline.elapsed(), backend, None,
            message="the time limit ran out while the scenario was built (particles "
                    "propagated over the look-ahead); give more time, a shorter look-ahead or "
                    "fewer particles"))
    result = BACKENDS.solve(backend, problem, time_limit_s=max(1e-3, deadline.remaining()),
                            seed=seed)
    return dataclasses.replace(result, runtime_s=deadline.elapsed())
