"""Greedy, lazy greedy, exact IP, brute force and auto on random small instances."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import AssignmentProblem, solve
from searchtrack.plan.assign.branch_and_bound import solve_branch_and_bound
from searchtrack.plan.assign.brute import solve_brute_force
from searchtrack.plan.assign.exact import solve_exact
from searchtrack.plan.assign.greedy import solve_greedy, solve_lazy_greedy
from searchtrack.plan.assign.objectives import ExpectedDetectionsFunction

from .helpers import DiscSensor, random_problem


@pytest.mark.parametrize("objective", ["end", "mi"])
@pytest.mark.parametrize("seed", range(8))
def test_greedy_at_least_half_of_brute_force(objective: str, seed: int) -> None:
    """Greedy and lazy greedy reach at least half the enumerated optimum; lazy equals greedy."""
    rng = np.random.default_rng(seed)
    p = random_problem(rng, robots=3, actions=4, steps=1, particles=50, objective=objective,
                       gaussian=seed % 2 == 1)
    best = solve_brute_force(p)
    g = solve_greedy(p)
    lazy = solve_lazy_greedy(p)
    assert best.status is Status.OPTIMAL and best.objective is not None
    assert g.objective is not None and lazy.objective is not None
    assert g.objective >= 0.5 * best.objective - 1e-9
    assert g.objective <= best.objective + 1e-9
    assert lazy.objective == pytest.approx(g.objective, abs=1e-9)
    if g.bound is not None:
        assert g.bound >= best.objective - 1e-9


@pytest.mark.parametrize("solver", ["scip", "cpsat", "bnb", "scip-unreduced"])
@pytest.mark.parametrize("seed", range(6))
def test_exact_matches_brute_force(solver: str, seed: int) -> None:
    """The IP's and branch and bound's plans have the brute-force optimal END, valid bounds."""
    rng = np.random.default_rng(100 + seed)
    p = random_problem(rng, robots=3, actions=5, steps=2, particles=60, gaussian=seed % 2 == 0)
    best = solve_brute_force(p)
    if solver == "bnb":
        res = solve_branch_and_bound(p)
    elif solver == "scip-unreduced":
        res = solve_exact(p, pieces=4, reduce=False)
    else:
        res = solve_exact(p, solver=solver)  # type: ignore[arg-type]
    assert best.objective is not None and res.objective is not None and res.bound is not None
    assert res.objective == pytest.approx(best.objective, rel=1e-6)
    assert res.bound >= best.objective - 1e-9
    if solver != "cpsat":
        assert res.status is Status.OPTIMAL
    assert res.plan is not None
    assert ExpectedDetectionsFunction(p).value(res.plan.selection) == pytest.approx(res.objective)


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


def test_bad_inputs() -> None:
    """Bad fields, backends, limits and objective/backend mismatches raise naming the field."""
    rng = np.random.default_rng(0)
    p = random_problem(rng, objective="mi")
    with pytest.raises(InvalidInputError, match="backend"):
        solve(p, backend="exact")
    with pytest.raises(InvalidInputError, match="backend"):
        solve(p, backend="nope")
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve(p, backend="greedy", time_limit_s=0.0)
    with pytest.raises(InvalidInputError, match="seed"):
        solve(p, backend="greedy", seed=-1)
    acts = (np.zeros((2, 1, 3)),)
    belief = WeightedParticles(np.zeros((3, 2)), np.ones(3))
    with pytest.raises(InvalidInputError, match="weights"):
        WeightedParticles(np.zeros((3, 2)), -np.ones(3))
    with pytest.raises(InvalidInputError, match="positions"):
        WeightedParticles(np.zeros((3, 4)), np.ones(3))
    with pytest.raises(InvalidInputError, match=r"belief\.weights"):
        AssignmentProblem(acts, _RawBelief(np.zeros((3, 2)), -np.ones(3)), DiscSensor())
    with pytest.raises(InvalidInputError, match="belief"):
        AssignmentProblem(acts, np.zeros((3, 2)), DiscSensor())  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="actions"):
        AssignmentProblem((np.zeros((0, 1, 3)),), belief, DiscSensor())
    with pytest.raises(InvalidInputError, match="actions"):
        AssignmentProblem((np.zeros((2, 1, 3)), np.zeros((2, 2, 3))), belief, DiscSensor())
    with pytest.raises(InvalidInputError, match="sensor"):
        AssignmentProblem(acts, belief, object())  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="objective"):
        AssignmentProblem(acts, belief, DiscSensor(), objective="end")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="min_separation_m"):
        AssignmentProblem(acts, belief, DiscSensor(), min_separation_m=-1)
    with pytest.raises(InvalidInputError, match="origins"):
        AssignmentProblem(acts, belief, DiscSensor(), origins=np.zeros((2, 3)))


class _RawBelief:
    """A particle belief that checks nothing (so the problem's own checks are exercised)."""

    def __init__(self, positions: np.ndarray, weights: np.ndarray) -> None:
        self.positions = positions
        self.weights = weights

    def expected_count(self) -> float:
        return float(self.weights.sum())


def test_tiny_time_limit_returns_a_valid_result() -> None:
    """A 1 ms limit still yields a well-formed result (a plan or an honest no-solution)."""
    p = random_problem(np.random.default_rng(2), robots=4, actions=8, steps=2)
    for backend in ("greedy", "exact", "exact_bnb", "brute_force", "auto"):
        res = solve(p, backend=backend, time_limit_s=1e-3)
        assert res.status in (Status.OPTIMAL, Status.FEASIBLE, Status.NO_SOLUTION)
        assert (res.plan is not None) == res.status.has_plan


@pytest.mark.parametrize("seed", range(4))
def test_bnb_and_ip_agree_with_collisions_on_larger_instances(seed: int) -> None:
    """Branch and bound and the IP find the same optimal END with collision constraints."""
    rng = np.random.default_rng(300 + seed)
    p = random_problem(rng, robots=4, actions=8, steps=2, particles=150, separation=12.0)
    a, b = solve_branch_and_bound(p, time_limit_s=30.0), solve_exact(p, time_limit_s=30.0)
    brute = solve_brute_force(p, time_limit_s=30.0)
    assert a.status is Status.OPTIMAL and b.status is Status.OPTIMAL
    assert a.objective == pytest.approx(brute.objective, rel=1e-9)
    assert b.objective == pytest.approx(brute.objective, rel=1e-9)


def test_dominated_actions_are_reduced_exactly() -> None:
    """A copy of an action and an action covering a subset are dropped from the program."""
    from searchtrack.plan.assign.exact import undominated

    ell = np.array([[1.0, 1.0, 0.5, 0.0], [0.0, 0.0, 0.0, 2.0], [1.0, 1.0, 1.0, 0.0]])
    kept, column_of = undominated(ell, np.ones(4, dtype=bool))
    assert kept.tolist() == [0, 3]
    assert column_of.tolist() == [0, 0, 0, 1]
    kept, _ = undominated(ell, np.array([False, True, True, True]))
    assert kept.tolist() == [0, 1, 3]
