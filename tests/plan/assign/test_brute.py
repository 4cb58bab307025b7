"""Brute-force assignment: the size check, hand-computed optima with and without collision
pruning, and the time limit."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import AssignmentProblem, MutualInformation
from searchtrack.plan.assign.brute import (
    MAX_JOINT,
    joint_size,
    solve_brute_force,
    supports_brute_force,
)

from .helpers import DiscSensor, random_problem

OVER_A = [0.0, 0.0, 20.0]
OVER_B = [100.0, 0.0, 20.0]


def two_uavs_two_particles(separation: float) -> AssignmentProblem:
    """Particle A (weight 1) at x = 0, B (weight 0.1) at x = 100; each UAV can sit over either."""
    acts = np.array([[OVER_A], [OVER_B]])
    belief = WeightedParticles(np.array([[0.0, 0.0], [100.0, 0.0]]), np.array([1.0, 0.1]))
    return AssignmentProblem((acts, acts), belief, DiscSensor(radius_m=5.0),
                             min_separation_m=separation)


def test_joint_size_and_support() -> None:
    """Π_r |Q^r| counts the joint actions; above MAX_JOINT brute force declines with the count."""
    p = random_problem(np.random.default_rng(0), robots=1)
    sizes = AssignmentProblem(tuple(np.zeros((a, 1, 3)) for a in (2, 3, 4)), p.belief, p.sensor)
    assert joint_size(sizes) == 24
    assert supports_brute_force(sizes) is None
    big = AssignmentProblem((np.zeros((1415, 1, 3)),) * 2, p.belief, p.sensor)
    assert joint_size(big) == 1415**2 > MAX_JOINT
    reason = supports_brute_force(big)
    assert reason is not None and str(1415**2) in reason


def test_optimum_without_collisions() -> None:
    """Both UAVs over A: END 1 − 0.2² = 0.96 beats A and B, 0.8 + 0.08 = 0.88."""
    res = solve_brute_force(two_uavs_two_particles(0.0))
    assert res.status is Status.OPTIMAL and res.plan is not None
    assert res.plan.actions == (0, 0)
    assert res.objective == res.bound == pytest.approx(0.96, rel=1e-12)


def test_optimum_with_collisions() -> None:
    """With 5 m separation the UAVs cannot share a spot: 0.88, the first split (0, 1) kept on
    the tie with (1, 0)."""
    res = solve_brute_force(two_uavs_two_particles(5.0))
    assert res.status is Status.OPTIMAL and res.plan is not None
    assert res.plan.actions == (0, 1)
    assert res.objective == res.bound == pytest.approx(0.88, rel=1e-12)
    np.testing.assert_array_equal(res.plan.poses, [[OVER_A], [OVER_B]])


def test_single_uav_takes_its_best_action() -> None:
    """With one UAV the enumeration is empty and the best gain decides: action 1, END 0.8."""
    acts = np.array([[OVER_B], [OVER_A]])
    p = AssignmentProblem((acts,), WeightedParticles(np.zeros((1, 2)), np.ones(1)), DiscSensor())
    res = solve_brute_force(p)
    assert res.status is Status.OPTIMAL and res.plan is not None and res.plan.actions == (1,)
    assert res.objective == pytest.approx(0.8, rel=1e-12)


def test_time_limit_before_any_plan() -> None:
    """A limit that has expired at the first look gives NO_SOLUTION, no plan, no bound."""
    res = solve_brute_force(random_problem(np.random.default_rng(1)), time_limit_s=1e-9)
    assert res.status is Status.NO_SOLUTION and res.plan is None and res.bound is None
    assert "time limit" in res.message


def test_monte_carlo_mi_is_never_claimed_optimal() -> None:
    """Above ``exact_max`` measurements the MI values are estimates: the enumeration's best is
    FEASIBLE without a bound, and says why."""
    rng = np.random.default_rng(5)
    base = random_problem(rng, robots=2, actions=3, steps=2)
    problem = dataclasses.replace(base, objective=MutualInformation(exact_max=3, samples=200))
    result = solve_brute_force(problem)
    assert result.status is Status.FEASIBLE and result.bound is None
    assert "Monte Carlo" in result.message
    exact = solve_brute_force(dataclasses.replace(base, objective=MutualInformation()))
    assert exact.status is Status.OPTIMAL
