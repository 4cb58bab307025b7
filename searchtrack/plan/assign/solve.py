"""Solve an assignment problem by backend name; ``auto`` answers greedily, then proves or improves
the answer within the time limit with an exact solver: the branch and bound for END (faster than
the integer programs, ``benchmarks/assign.py``), enumeration for mutual information when the
joint action space is small enough. The integer programs import OR-Tools within their time
(:func:`~searchtrack.core.loading.loaded_within`): a first call whose limit runs out while it
loads answers ``NO_SOLUTION``."""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

from searchtrack.core.deadline import Deadline
from searchtrack.core.loading import loaded_within, still_loading
from searchtrack.core.registry import Backend, Registry, heuristic_then_exact
from searchtrack.core.result import Result
from searchtrack.plan.assign.branch_and_bound import solve_branch_and_bound
from searchtrack.plan.assign.brute import solve_brute_force, supports_brute_force
from searchtrack.plan.assign.greedy import solve_greedy, solve_lazy_greedy
from searchtrack.plan.assign.objectives import MutualInformationFunction, coverage_only
from searchtrack.plan.assign.problem import Assignment, AssignmentProblem
from searchtrack.plan.assign.validate import answer_problems

if TYPE_CHECKING:
    from searchtrack.plan.assign.exact import MipSolver


def _program(problem: AssignmentProblem, time_limit_s: float, seed: int, backend: str,
             solver: MipSolver, library: str) -> Result[Assignment]:
    deadline = Deadline(time_limit_s)
    if not loaded_within(library, deadline):
        return still_loading(backend, "OR-Tools", deadline)
    from searchtrack.plan.assign.exact import solve_exact

    return solve_exact(problem, time_limit_s=max(1e-3, deadline.remaining()), seed=seed,
                       solver=solver)


def _exact(problem: AssignmentProblem, *, time_limit_s: float, seed: int) -> Result[Assignment]:
    return _program(problem, time_limit_s, seed, "exact", "scip", "ortools.linear_solver.pywraplp")


def _exact_cpsat(problem: AssignmentProblem, *, time_limit_s: float,
                 seed: int) -> Result[Assignment]:
    return _program(problem, time_limit_s, seed, "exact_cpsat", "cpsat",
                    "ortools.sat.python.cp_model")


def _nlp(problem: AssignmentProblem, *, time_limit_s: float, seed: int) -> Result[Assignment]:
    from searchtrack.plan.assign.nlp import NLPLimits, solve_nlp

    return solve_nlp(problem, NLPLimits(), time_limit_s=time_limit_s, seed=seed)


def _nlp_supports(problem: AssignmentProblem) -> str | None:
    from searchtrack.plan.assign.nlp import nlp_supports

    return nlp_supports(problem)


def _auto(problem: AssignmentProblem, *, time_limit_s: float, seed: int) -> Result[Assignment]:
    exact = (solve_branch_and_bound if problem.objective.coverage
             else solve_brute_force if supports_brute_force(problem) is None else None)

    def prove(problem: AssignmentProblem, first: Result[Assignment], limit_s: float,
              seed: int) -> Result[Assignment]:
        assert exact is not None
        return exact(problem, time_limit_s=limit_s, seed=seed)

    return heuristic_then_exact(problem, solve_lazy_greedy, prove if exact else None,
                                time_limit_s=time_limit_s, seed=seed,
                                heuristic_limit_s=time_limit_s)


BACKENDS: Registry[AssignmentProblem, Assignment] = Registry("assignment",
                                                            validator=answer_problems)
BACKENDS.register(Backend("auto", _auto, True,
                          "lazy greedy at once, then exact in the limit: branch and bound (END), "
                          "enumeration (MI, small problems)"))
BACKENDS.register(Backend("greedy", solve_greedy, False,
                          "003 Algorithm 1: best (UAV, action) pair first; >= 1/2 OPT"))
BACKENDS.register(Backend("lazy_greedy", solve_lazy_greedy, False,
                          "greedy with a priority queue of stale gains (same answer)"))
BACKENDS.register(Backend("exact", _exact, True,
                          "END integer program, outer approximation + cuts, SCIP",
                          supports=coverage_only))
BACKENDS.register(Backend("exact_cpsat", _exact_cpsat, True,
                          "the same program scaled to integers, CP-SAT", supports=coverage_only))
BACKENDS.register(Backend("exact_bnb", solve_branch_and_bound, True,
                          "END branch and bound with submodular bounds (fastest exact)",
                          supports=coverage_only))
BACKENDS.register(Backend("brute_force", solve_brute_force, True,
                          "enumerate every joint action (tiny problems)",
                          supports=supports_brute_force))
BACKENDS.register(Backend("nlp", _nlp, False,
                          "CasADi + Ipopt: move the greedy waypoints continuously (smooth END)",
                          supports=_nlp_supports))


def solve(problem: AssignmentProblem, *, backend: str = "auto", time_limit_s: float = 1.0,
          seed: int = 0) -> Result[Assignment]:
    """Assign one action per UAV with the named backend within ``time_limit_s`` seconds.

    Raises
    ------
    InvalidInputError
        Unknown backend, a backend that cannot take the problem, a bad limit or seed.
    """
    result = BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)
    if result.plan is None:
        return result
    evaluator = problem.objective.evaluator(problem)
    if not isinstance(evaluator, MutualInformationFunction):
        return result
    # The MI's series error for the plan's actions: how far the objective may be off.
    selection = list(enumerate(result.plan.actions))
    stats = {**result.stats, "objective_error": evaluator.error(selection)}
    return dataclasses.replace(result, stats=stats)
