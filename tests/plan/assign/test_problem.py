"""The assignment problem and its plan: validation naming the field, the cached detection,
hit, miss and log-miss tensors, collision pruning and ``Assignment``."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import Assignment, AssignmentProblem, solve

from .helpers import DiscSensor, random_problem


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


def test_more_bad_fields() -> None:
    """Non-finite poses, pose sizes that differ and bad particle positions raise naming the
    field."""
    belief = WeightedParticles(np.zeros((3, 2)), np.ones(3))
    bad = np.zeros((2, 1, 3))
    bad[1, 0, 2] = np.nan
    with pytest.raises(InvalidInputError, match=r"actions\[0\]"):
        AssignmentProblem((bad,), belief, DiscSensor())
    with pytest.raises(InvalidInputError, match=r"actions\[1\]"):
        AssignmentProblem((np.zeros((2, 1, 3)), np.zeros((2, 1, 4))), belief, DiscSensor())
    with pytest.raises(InvalidInputError, match=r"actions\[0\]"):
        AssignmentProblem((np.zeros((2, 1, 2)),), belief, DiscSensor())
    with pytest.raises(InvalidInputError, match=r"belief\.positions"):
        AssignmentProblem((np.zeros((2, 1, 3)),), _RawBelief(np.zeros((3, 4)), np.ones(3)),
                          DiscSensor())
    with pytest.raises(InvalidInputError, match=r"belief\.weights"):
        AssignmentProblem((np.zeros((2, 1, 3)),), _RawBelief(np.zeros((3, 2)), np.ones(2)),
                          DiscSensor())


def test_sizes_and_read_only_copies() -> None:
    """R, T and |Q^r| read off the arrays, which are read-only copies of the caller's."""
    acts = [np.zeros((2, 3, 5)), np.ones((4, 3, 5))]
    p = AssignmentProblem(tuple(acts), WeightedParticles(np.zeros((3, 2)), np.ones(3)),
                          DiscSensor())
    assert (p.robots, p.horizon, p.n_actions(0), p.n_actions(1)) == (2, 3, 2, 4)
    acts[1][0, 0, 0] = 9.0
    assert p.actions[1][0, 0, 0] == 1.0
    assert not p.actions[0].flags.writeable and not p.weights.flags.writeable


def test_detection_hit_miss_and_log_miss() -> None:
    """One UAV, two actions of two poses over particles P0 (x = 0) and P1 (x = 50), p_d = 0.8
    inside 10 m: action 0 looks twice at P0 (hit 1 − 0.2² = 0.96), action 1 once at each
    (hit 0.8 and 0.8)."""
    acts = np.array([[[0.0, 0.0, 20.0], [0.0, 0.0, 20.0]],
                     [[0.0, 0.0, 20.0], [50.0, 0.0, 20.0]]])
    belief = WeightedParticles(np.array([[0.0, 0.0], [50.0, 0.0]]), np.ones(2))
    p = AssignmentProblem((acts,), belief, DiscSensor())
    np.testing.assert_allclose(p.detection[0], [[[0.8, 0.0], [0.8, 0.0]],
                                                [[0.8, 0.0], [0.0, 0.8]]])
    np.testing.assert_allclose(p.hit[0], [[0.96, 0.0], [0.8, 0.8]], rtol=1e-12)
    np.testing.assert_allclose(p.miss[0], [[0.04, 1.0], [0.2, 0.2]], rtol=1e-12)
    ell = -math.log(0.2)
    np.testing.assert_allclose(p.log_miss[0], [[2 * ell, 0.0], [ell, ell]], rtol=1e-12)


def test_one_step_hit_is_a_view_of_the_detection() -> None:
    """For T = 1 the hit probabilities are the detection tensor itself (no copy)."""
    p = random_problem(np.random.default_rng(0), robots=2, steps=1)
    assert all(np.shares_memory(h, d) for h, d in zip(p.hit, p.detection, strict=True))


def test_log_miss_caps_certain_detection() -> None:
    """p_d = 1 gives ℓ = −log(1e-9), finite, rather than infinity."""
    p = AssignmentProblem((np.array([[[0.0, 0.0, 20.0]]]),),
                          WeightedParticles(np.zeros((1, 2)), np.ones(1)), DiscSensor(peak=1.0))
    assert p.log_miss[0][0, 0] == pytest.approx(-math.log(1e-9), rel=1e-6)


def test_conflicts_and_compatible_actions() -> None:
    """Actions at x = 0, 3 and 10 with 5 m separation: the pairs closer than 5 m conflict, and
    ``compatible`` masks them from either side."""
    acts = np.array([[[0.0, 0.0, 20.0]], [[3.0, 0.0, 20.0]], [[10.0, 0.0, 20.0]]])
    belief = WeightedParticles(np.zeros((1, 2)), np.ones(1))
    p = AssignmentProblem((acts, acts), belief, DiscSensor(), min_separation_m=5.0)
    np.testing.assert_array_equal(p.conflicts[(0, 1)], [[True, True, False],
                                                        [True, True, False],
                                                        [False, False, True]])
    np.testing.assert_array_equal(p.compatible(((0, 0),), 1), [False, False, True])
    np.testing.assert_array_equal(p.compatible(((1, 2),), 0), [True, True, False])
    np.testing.assert_array_equal(p.compatible((), 0), [True, True, True])
    assert AssignmentProblem((acts, acts), belief, DiscSensor()).conflicts == {}


def test_conflicts_compare_common_steps_only() -> None:
    """Two UAVs swapping ends of a 20 m segment are 20 m apart at each step: no conflict at a
    separation of 5 m, though each visits the other's spot."""
    a = np.array([[[0.0, 0.0, 20.0], [20.0, 0.0, 20.0]]])
    b = np.array([[[20.0, 0.0, 20.0], [0.0, 0.0, 20.0]]])
    p = AssignmentProblem((a, b), WeightedParticles(np.zeros((1, 2)), np.ones(1)), DiscSensor(),
                          min_separation_m=5.0)
    assert p.conflicts == {}
    crowded = AssignmentProblem((a, b), p.belief, DiscSensor(), min_separation_m=21.0)
    np.testing.assert_array_equal(crowded.conflicts[(0, 1)], [[True]])


def test_assignment_of_stacks_the_chosen_poses() -> None:
    """``Assignment.of`` flies action r of each UAV; ``selection`` pairs UAVs with actions."""
    p = random_problem(np.random.default_rng(2), robots=3, actions=4, steps=2)
    plan = Assignment.of(p, [np.int64(3), 0, 2])  # type: ignore[list-item]
    assert plan.actions == (3, 0, 2) and all(type(a) is int for a in plan.actions)
    assert plan.selection == ((0, 3), (1, 0), (2, 2))
    np.testing.assert_array_equal(plan.poses, np.stack([p.actions[0][3], p.actions[1][0],
                                                        p.actions[2][2]]))
