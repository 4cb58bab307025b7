"""Greedy and lazy greedy assignment (paper 003 Algorithm 1): the ½ guarantee, the online bound,
tie-breaking and the evaluation counts."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import AssignmentProblem, MutualInformation
from searchtrack.plan.assign.brute import solve_brute_force
from searchtrack.plan.assign.greedy import online_bound, solve_greedy, solve_lazy_greedy

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


def test_online_bound_of_a_hand_instance() -> None:
    """One unit particle under two UAVs (p_d = 0.8): END 1 − 0.2² = 0.96 and the bound adds each
    UAV's gain 0.8 · 0.04 given the plan, 0.96 + 2 · 0.032 = 1.024 (not proven optimal)."""
    over = np.array([[[0.0, 0.0, 20.0]]])
    p = AssignmentProblem((over, over), WeightedParticles(np.zeros((1, 2)), np.ones(1)),
                          DiscSensor())
    for solver in (solve_greedy, solve_lazy_greedy):
        res = solver(p)
        assert res.status is Status.FEASIBLE and res.plan is not None
        assert res.objective == pytest.approx(0.96, rel=1e-12)
        assert res.bound == pytest.approx(1.024, rel=1e-12)


def test_online_bound_for_mutual_information() -> None:
    """For MI the bound is 2 f(G) without conflicts and none with them."""
    p = random_problem(np.random.default_rng(1), robots=2, actions=3, particles=30,
                       objective="mi")
    f = p.objective.evaluator(p)
    assert online_bound(p, f, ((0, 0), (1, 2)), 0.25) == 0.5
    crowded = AssignmentProblem(p.actions, p.belief, p.sensor, objective=MutualInformation(),
                                min_separation_m=1e3)
    assert crowded.conflicts
    assert online_bound(crowded, f, ((0, 0), (1, 2)), 0.25) is None


def test_saturated_coverage_is_proven_optimal() -> None:
    """With p_d = 1 over the only particle no action can add anything: the bound equals the
    value and greedy reports OPTIMAL with the covering action (index 1)."""
    acts = np.array([[[100.0, 0.0, 20.0]], [[0.0, 0.0, 20.0]]])
    p = AssignmentProblem((acts,), WeightedParticles(np.zeros((1, 2)), np.full(1, 2.0)),
                          DiscSensor(peak=1.0))
    for solver in (solve_greedy, solve_lazy_greedy):
        res = solver(p)
        assert res.status is Status.OPTIMAL and res.plan is not None
        assert res.plan.actions == (1,)
        assert res.objective == res.bound == pytest.approx(2.0)


def test_ties_go_to_the_lowest_uav() -> None:
    """Two UAVs tie on the unit particle A: the lower-index UAV takes it. When that UAV could
    also reach the 0.5 particle B, greedy gets 0.8 + 0.16 = 0.96 against the optimum
    0.8 + 0.4 = 1.2; with the UAVs swapped it finds the optimum."""
    pos = np.array([[0.0, 0.0], [100.0, 0.0]])
    belief = WeightedParticles(pos, np.array([1.0, 0.5]))
    both = np.array([[[0.0, 0.0, 20.0]], [[100.0, 0.0, 20.0]]])
    only_a = np.array([[[0.0, 0.0, 20.0]]])
    trapped = AssignmentProblem((both, only_a), belief, DiscSensor())
    swapped = AssignmentProblem((only_a, both), belief, DiscSensor())
    for solver in (solve_greedy, solve_lazy_greedy):
        res = solver(trapped)
        assert res.plan is not None and res.plan.actions == (0, 0)
        assert res.objective == pytest.approx(0.96, rel=1e-12)
        res = solver(swapped)
        assert res.plan is not None and res.plan.actions == (0, 1)
        assert res.objective == pytest.approx(1.2, rel=1e-12)
    assert solve_brute_force(trapped).objective == pytest.approx(1.2, rel=1e-12)


def test_no_collision_free_action_names_the_uav() -> None:
    """When UAV 0's only action blocks every action of UAV 1, greedy reports NO_SOLUTION
    naming UAV 1."""
    acts = np.array([[[0.0, 0.0, 20.0]]])
    p = AssignmentProblem((acts, acts + 1.0), WeightedParticles(np.zeros((1, 2)), np.ones(1)),
                          DiscSensor(), min_separation_m=5.0)
    for solver in (solve_greedy, solve_lazy_greedy):
        res = solver(p)
        assert res.status is Status.NO_SOLUTION and res.plan is None
        assert "UAVs [1]" in res.message


def test_evaluation_counts() -> None:
    """Greedy evaluates every action of every unassigned UAV each round (12 + 8 + 4 = 24 for
    three UAVs of four actions); lazy greedy never evaluates more."""
    p = random_problem(np.random.default_rng(4), robots=3, actions=4)
    greedy, lazy = solve_greedy(p), solve_lazy_greedy(p)
    assert greedy.stats["evaluations"] == 24.0
    assert 12.0 <= lazy.stats["evaluations"] <= 24.0
