"""solve() by backend name: the registry, auto's hand-over, collision pruning and statuses
across every backend, determinism and tiny time limits."""

from __future__ import annotations

import importlib

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.assign import BACKENDS, AssignmentProblem, solve
from searchtrack.plan.assign import brute as brute_module
from searchtrack.plan.assign.branch_and_bound import solve_branch_and_bound
from searchtrack.plan.assign.brute import solve_brute_force
from searchtrack.plan.assign.exact import solve_exact
from searchtrack.plan.assign.greedy import solve_greedy

from .helpers import DiscSensor, random_problem


def test_collision_pruning_respected_by_every_backend() -> None:
    """Two UAVs whose best actions coincide must take separated actions."""
    acts = np.array([[[0.0, 0.0, 20.0]], [[30.0, 0.0, 20.0]]])
    pos = np.array([[0.0, 0.0], [1.0, 0.0], [30.0, 0.0]])
    w = np.array([1.0, 1.0, 0.1])
    p = AssignmentProblem((acts, acts), WeightedParticles(pos, w), DiscSensor(radius_m=5.0),
                          min_separation_m=5.0)
    for backend in ("greedy", "lazy_greedy", "exact", "exact_cpsat", "exact_bnb", "brute_force",
                    "auto"):
        res = solve(p, backend=backend, time_limit_s=5.0)
        assert res.plan is not None, backend
        assert res.plan.actions[0] != res.plan.actions[1], backend

def test_infeasible_when_every_pair_collides() -> None:
    """Brute force reports INFEASIBLE and greedy NO_SOLUTION when all joint actions collide."""
    acts = np.array([[[0.0, 0.0, 20.0]]])
    p = AssignmentProblem((acts, acts), WeightedParticles(np.zeros((2, 2)), np.ones(2)),
                          DiscSensor(), min_separation_m=1.0)
    assert solve_brute_force(p).status is Status.INFEASIBLE
    assert solve_greedy(p).status is Status.NO_SOLUTION
    assert solve_exact(p).status is Status.INFEASIBLE
    assert solve_branch_and_bound(p).status is Status.INFEASIBLE

def test_auto_reports_who_answered_and_is_optimal_on_small_end() -> None:
    """auto proves small END instances optimal and names the answering backend."""
    p = random_problem(np.random.default_rng(7), robots=3, actions=5, steps=1)
    res = solve(p, backend="auto", time_limit_s=5.0)
    best = solve_brute_force(p)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(best.objective)
    assert "answered" in res.message

def test_auto_proves_small_mi_by_enumeration() -> None:
    """For mutual information auto enumerates a small joint action space after greedy and
    returns its optimum."""
    p = random_problem(np.random.default_rng(5), robots=3, actions=4, steps=1, particles=50,
                       objective="mi")
    res = solve(p, backend="auto", time_limit_s=10.0)
    best = solve_brute_force(p)
    assert res.status is Status.OPTIMAL
    assert res.objective == pytest.approx(best.objective)
    assert "brute_force" in res.message

def test_deterministic() -> None:
    """The same problem gives the same plans from every deterministic backend."""
    for backend in ("greedy", "lazy_greedy", "exact", "exact_bnb", "brute_force"):
        a = solve(random_problem(np.random.default_rng(3)), backend=backend)
        b = solve(random_problem(np.random.default_rng(3)), backend=backend)
        assert a.plan is not None and b.plan is not None
        assert a.plan.actions == b.plan.actions

def test_tiny_time_limit_returns_a_valid_result() -> None:
    """A 1 ms limit still yields a well-formed result (a plan or an honest no-solution)."""
    p = random_problem(np.random.default_rng(2), robots=4, actions=8, steps=2)
    for backend in ("greedy", "exact", "exact_bnb", "brute_force", "auto"):
        res = solve(p, backend=backend, time_limit_s=1e-3)
        assert res.status in (Status.OPTIMAL, Status.FEASIBLE, Status.NO_SOLUTION)
        assert (res.plan is not None) == res.status.has_plan


def test_registry_lists_the_backends() -> None:
    """Eight backends in registration order; the exact ones are auto, the integer programs, the
    branch and bound and brute force."""
    assert BACKENDS.names() == ["auto", "greedy", "lazy_greedy", "exact", "exact_cpsat",
                                "exact_bnb", "brute_force", "nlp"]
    exact = [n for n in BACKENDS.names() if BACKENDS.get(n).exact]
    assert exact == ["auto", "exact", "exact_cpsat", "exact_bnb", "brute_force"]
    assert all(BACKENDS.get(n).description for n in BACKENDS.names())


def test_auto_without_an_exact_stage_returns_the_greedy_answer(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """MI over a joint action space too large to enumerate: auto answers with lazy greedy alone
    (FEASIBLE, bound 2 f(G)), and brute force is refused by name."""
    monkeypatch.setattr(brute_module, "MAX_JOINT", 10)
    p = random_problem(np.random.default_rng(5), robots=3, actions=4, particles=30,
                       objective="mi")
    res = solve(p, backend="auto", time_limit_s=10.0)
    greedy = solve(p, backend="lazy_greedy")
    assert res.status is Status.FEASIBLE and res.objective is not None
    assert res.plan is not None and greedy.plan is not None
    assert res.message.startswith("auto: lazy_greedy answered")
    assert res.plan.actions == greedy.plan.actions
    assert res.bound == pytest.approx(2.0 * res.objective)
    with pytest.raises(InvalidInputError, match="backend"):
        solve(p, backend="brute_force")



def _smooth_end() -> AssignmentProblem:
    """Two UAVs, four two-step actions each, END with the Gaussian field of view: every backend,
    the NLP included, takes it."""
    p = random_problem(np.random.default_rng(13), robots=2, actions=4, steps=2, particles=40)
    return AssignmentProblem(p.actions, p.belief, GaussianFieldOfView(0.9, 8.0, 40.0))


@pytest.mark.parametrize("backend", ["greedy", "lazy_greedy", "exact", "exact_cpsat",
                                     "exact_bnb", "brute_force", "nlp"])
def test_every_backend_reports_its_registry_name(backend: str) -> None:
    """Each backend's result carries the name it is registered under (``exact``, not
    ``exact_scip``)."""
    result = solve(_smooth_end(), backend=backend, time_limit_s=10.0)
    assert result.plan is not None and result.backend == backend


@pytest.mark.parametrize(("objective", "stage"), [("end", "exact_bnb"), ("mi", "brute_force")])
def test_auto_reports_the_registry_name_of_the_answering_stage(objective: str,
                                                                stage: str) -> None:
    """auto's result names the exact stage whose plan it returns: the branch and bound for END,
    enumeration for mutual information."""
    p = random_problem(np.random.default_rng(5), robots=3, actions=4, particles=30,
                       objective=objective)
    result = solve(p, backend="auto", time_limit_s=10.0)
    assert result.status is Status.OPTIMAL and result.backend == stage


def test_a_limit_spent_loading_or_tools_answers_no_solution(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """While OR-Tools is still loading when the limit runs out, the integer programs answer
    NO_SOLUTION; ``auto`` (branch and bound) needs no OR-Tools."""
    solve_module = importlib.import_module("searchtrack.plan.assign.solve")

    monkeypatch.setattr(solve_module, "loaded_within", lambda name, deadline: False)
    p = random_problem(np.random.default_rng(3))
    for backend in ("exact", "exact_cpsat"):
        res = solve(p, backend=backend, time_limit_s=1.0)
        assert res.status is Status.NO_SOLUTION and "OR-Tools" in res.message, backend
    assert solve(p, backend="auto", time_limit_s=5.0).status is Status.OPTIMAL
