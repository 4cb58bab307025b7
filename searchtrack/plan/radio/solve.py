"""Solve a radio planning problem by backend name (Nguyen et al., §III-D, eq. 45).

``auto`` runs the beam search at once, then the exhaustive search in the time left, starting
from the beam's plan and on the beam's look-ahead, to improve it or prove it optimal
(:func:`~searchtrack.core.registry.heuristic_then_exact`); its result names the stage whose
plan it is. Every backend scores sequences on the same look-ahead draws for a given ``seed``.
"""

from __future__ import annotations

from searchtrack.core.registry import Backend, Registry, heuristic_then_exact
from searchtrack.core.result import Result
from searchtrack.plan.radio.backends import (
    solve_beam,
    solve_exhaustive,
    solve_greedy,
    solve_straight,
)
from searchtrack.plan.radio.problem import RadioPlan, RadioPlanProblem
from searchtrack.plan.radio.tree import Scorer
from searchtrack.plan.radio.validator import answer_problems


def _auto(problem: RadioPlanProblem, *, time_limit_s: float, seed: int) -> Result[RadioPlan]:
    shared: list[Scorer] = []

    def scorer() -> Scorer:   # one look-ahead for both stages (the same problem and seed)
        if not shared:
            shared.append(Scorer(problem, seed))
        return shared[0]

    def beam(p: RadioPlanProblem, *, time_limit_s: float, seed: int) -> Result[RadioPlan]:
        return solve_beam(p, time_limit_s=time_limit_s, seed=seed, scorer=scorer())

    def prove(p: RadioPlanProblem, first: Result[RadioPlan], limit_s: float,
              seed: int) -> Result[RadioPlan]:
        return solve_exhaustive(p, time_limit_s=limit_s, seed=seed, initial=first.plan,
                                scorer=scorer())

    return heuristic_then_exact(problem, beam, prove, time_limit_s=time_limit_s, seed=seed,
                                heuristic_limit_s=time_limit_s, tol=1e-9)


BACKENDS: Registry[RadioPlanProblem, RadioPlan] = Registry("radio planning",
                                                           validator=answer_problems)
BACKENDS.register(Backend("auto", _auto, True,
                          "beam at once, then exhaustive in the time left to improve or prove it"))
BACKENDS.register(Backend("exhaustive", solve_exhaustive, True,
                          "every sequence of H primitives (the paper's planner)"))
BACKENDS.register(Backend("beam", solve_beam, False,
                          "beam search of the look-ahead tree"))
BACKENDS.register(Backend("greedy", solve_greedy, False,
                          "the best primitive one planning interval at a time"))
BACKENDS.register(Backend("straight", solve_straight, False,
                          "straight sweep between the area's corners (Experiment 2 baseline)"))


def solve(problem: RadioPlanProblem, *, backend: str = "auto", time_limit_s: float = 1.0,
          seed: int = 0) -> Result[RadioPlan]:
    """Plan the UAV's next ``H`` planning intervals with the named backend within
    ``time_limit_s``; ``seed`` fixes the look-ahead draws.

    Raises
    ------
    InvalidInputError
        Unknown backend, a bad time limit or seed.
    """
    return BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)
