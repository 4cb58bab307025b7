"""Every assignment backend on a catalogue of small problems whose optimum brute force knows."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.models.footprint import GaussianFieldOfView
from searchtrack.plan.assign import (
    BACKENDS,
    AssignmentProblem,
    ExpectedDetections,
    MutualInformation,
    solve,
)
from searchtrack.plan.assign.brute import solve_brute_force

from .helpers import DiscSensor, random_problem


def two_clusters() -> AssignmentProblem:
    """Two UAVs, two unit clusters 40 m apart, each UAV able to sit over either: the optimum
    covers both, END = 2 × 0.8 = 1.6."""
    over = np.array([[[0.0, 0.0, 20.0]], [[40.0, 0.0, 20.0]]])
    pos = np.array([[0.0, 0.0], [40.0, 0.0]])
    return AssignmentProblem((over, over), WeightedParticles(pos, np.ones(2)), DiscSensor(),
                             name="two clusters")


def greedy_trap() -> AssignmentProblem:
    """Unit clusters at x = 0 and 8 m, a 0.9 cluster at 100 m. UAV 0 covers the pair or the far
    cluster, UAV 1 only the pair: greedy gives UAV 0 the pair (1.6 + 0.32 = 1.92), the optimum
    sends it to the far cluster (0.72 + 1.6 = 2.32)."""
    pos = np.array([[0.0, 0.0], [8.0, 0.0], [100.0, 0.0]])
    w = np.array([1.0, 1.0, 0.9])
    a0 = np.array([[[4.0, 0.0, 20.0]], [[100.0, 0.0, 20.0]]])
    a1 = np.array([[[4.0, 0.0, 20.0]], [[200.0, 0.0, 20.0]]])
    return AssignmentProblem((a0, a1), WeightedParticles(pos, w), DiscSensor(radius_m=6.5),
                             name="greedy trap")


def with_collisions() -> AssignmentProblem:
    """Random END instance with collision pruning."""
    return random_problem(np.random.default_rng(11), robots=3, actions=4, steps=2,
                          particles=40, separation=12.0)


def mutual_information() -> AssignmentProblem:
    """Random binary-MI instance (exact MI: R·T ≤ 12 measurements)."""
    p = random_problem(np.random.default_rng(12), robots=3, actions=3, steps=1, particles=30)
    return AssignmentProblem(p.actions, p.belief, p.sensor, objective=MutualInformation())


def smooth_footprint() -> AssignmentProblem:
    """END with the differentiable Gaussian field of view (the NLP's sensor)."""
    p = random_problem(np.random.default_rng(13), robots=2, actions=4, steps=2, particles=40)
    return AssignmentProblem(p.actions, p.belief, GaussianFieldOfView(0.9, 8.0, 40.0),
                             objective=ExpectedDetections(), origins=p.actions[0][:2, 0])


CATALOGUE: dict[str, Callable[[], AssignmentProblem]] = {
    "two_clusters": two_clusters, "greedy_trap": greedy_trap, "with_collisions": with_collisions,
    "mutual_information": mutual_information, "smooth_footprint": smooth_footprint,
}


def test_known_optima() -> None:
    """Brute force, the reference below, finds the hand-computed optima; greedy falls in the
    trap."""
    best = solve_brute_force(two_clusters())
    assert best.objective == pytest.approx(1.6, rel=1e-12)
    assert best.plan is not None and sorted(best.plan.actions) == [0, 1]
    trap = solve_brute_force(greedy_trap())
    assert trap.objective == pytest.approx(2.32, rel=1e-12)
    assert trap.plan is not None and trap.plan.actions == (1, 0)
    assert solve(greedy_trap(), backend="greedy").objective == pytest.approx(1.92, rel=1e-12)


@pytest.mark.parametrize("name", sorted(CATALOGUE))
@pytest.mark.parametrize("backend", BACKENDS.names())
def test_backend_on_catalogue(backend: str, name: str) -> None:
    """Exact backends reach the brute-force optimum with a valid bound; heuristics return a
    collision-free plan whose value is what they report, greedy at least half the optimum; a
    backend that cannot take the problem is refused naming ``backend``."""
    problem = CATALOGUE[name]()
    chosen = BACKENDS.get(backend)
    reason = chosen.supports(problem)
    if reason is not None:
        with pytest.raises(InvalidInputError, match="backend") as refused:
            solve(problem, backend=backend, time_limit_s=1.0)
        assert refused.value.field == "backend" and refused.value.reason == reason
        return
    best = solve_brute_force(problem)
    assert best.status is Status.OPTIMAL and best.objective is not None
    result = solve(problem, backend=backend, time_limit_s=20.0)
    assert result.status.has_plan and result.plan is not None and result.objective is not None
    plan = result.plan
    assert all(problem.compatible(plan.selection[:r], r)[a] for r, a in plan.selection)
    if chosen.exact:
        assert result.objective == pytest.approx(best.objective, rel=1e-6)
        assert result.bound is not None and result.bound >= best.objective - 1e-9
    elif backend == "nlp":  # moves the waypoints off the candidates: never below greedy
        greedy = solve(problem, backend="greedy")
        assert greedy.objective is not None
        assert result.objective >= greedy.objective - 1e-9
    else:
        assert result.objective <= best.objective + 1e-9
        assert result.objective >= 0.5 * best.objective - 1e-9
        value = problem.objective.evaluator(problem).value(plan.selection)
        assert result.objective == pytest.approx(value, rel=1e-12)
