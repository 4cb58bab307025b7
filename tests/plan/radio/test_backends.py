"""Backends on situations with a known answer: the void constraint steers around a tag ahead,
the least-violating plan when nothing is feasible, information draws the UAV to an uncertain
tag, the straight baseline, and the relations between backends."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.models.radio import straight_sweep_heading
from searchtrack.plan.radio.backends import (
    solve_beam,
    solve_exhaustive,
    solve_greedy,
    solve_straight,
)
from searchtrack.plan.radio.tree import Scorer

from .helpers import POSE, belief, problem, spread_belief, surrounded, tag_ahead
from .test_search import every_sequence


def test_constraint_steers_around_a_tag_ahead() -> None:
    """Sequences that fly into a certain tag 100 m ahead break the constraint; the plan
    keeps every void probability above P_vmin and stays over r_min from the tag."""
    p = problem(tag_ahead(), horizon=2, plan_particles=60)
    res = solve_exhaustive(p)
    assert res.status is Status.OPTIMAL and res.plan is not None and res.plan.feasible
    assert res.plan.min_void > 0.9
    scored = every_sequence(Scorer(p, 0))
    east = [k for seq, k, _ in scored if seq[0] == 2]  # Δ = 0: straight on, into the tag
    assert east and not any(k[0] for k in east)
    assert sum(not k[0] for _, k, _ in scored) < len(scored)
    distance = np.hypot(res.plan.path[:, 0] - 700.0, res.plan.path[:, 1] - 600.0)
    assert distance.min() > 50.0


def test_unconstrained_plan_may_fly_into_it() -> None:
    """With P_vmin = 0 every sequence is feasible: the reward alone decides, and it flies
    straight over the tag (so the constraint above is what steers)."""
    res = solve_exhaustive(problem(tag_ahead(), horizon=2, plan_particles=60, p_void_min=0.0))
    assert res.status is Status.OPTIMAL and res.plan is not None and res.plan.feasible
    assert res.plan.headings[0] == pytest.approx(0.0) and res.plan.min_void < 0.9


@pytest.mark.parametrize("reward", ["renyi", "cs"])
def test_nothing_feasible_gives_the_least_violating_plan(reward: str) -> None:
    """Surrounded by certain tags: INFEASIBLE, no objective, the plan of the least total
    violation over all sequences as its fallback, flagged and proven so; beam answers with a
    fallback too (INFEASIBLE here: its beam dropped nothing, so it saw every sequence)."""
    p = problem(surrounded(), horizon=2, plan_particles=40, reward=reward)
    res = solve_exhaustive(p)
    assert res.status is Status.INFEASIBLE and res.objective is None
    assert res.plan is not None and res.fallback is res.plan and not res.plan.feasible
    assert res.stats["proven_infeasible"] == 1.0
    least = min(plan.violation(0.9) for _, _, plan in every_sequence(Scorer(p, 0)))
    assert res.plan.violation(0.9) == pytest.approx(least, rel=1e-12)
    beam = solve_beam(p)
    assert beam.status is Status.INFEASIBLE and beam.objective is None
    assert beam.plan is not None and not beam.plan.feasible


@pytest.mark.parametrize(("reward", "alpha"), [("renyi", 0.5), ("cs", 0.5), ("renyi", 1.0)])
def test_information_draws_the_uav_to_an_uncertain_tag(reward: str, alpha: float) -> None:
    """A tag of uncertain existence 350 m ahead: flying toward it earns more than flying away
    (H = 1, no constraint, the paper's reward: no exploration; the short-range calibration, so
    that flying away loses the tag), and the plan's heading points toward it."""
    b = belief([[950.0, 600.0], [1450.0, 50.0], [50.0, 1450.0], [1450.0, 1450.0]],
               [0.6, 0.01, 0.01, 0.01], spread_m=80.0)
    p = problem(b, horizon=1, plan_particles=150, reward=reward, alpha=alpha, p_void_min=0.0,
                explore_existence=0.0, calibration="unscaled")
    rewards = {seq[0]: plan.rewards[0] for seq, _, plan in every_sequence(Scorer(p, 0))}
    toward, away = rewards[2], rewards[0]  # Δ = 0 and Δ = −π from heading east
    assert toward > 1.5 * away > 0.0
    res = solve_exhaustive(p)
    assert res.plan is not None and math.cos(res.plan.headings[0]) > 0.5


def test_straight_baseline() -> None:
    """The sweep heading from each interval's first pose; scored; never proven."""
    p = problem(spread_belief(), horizon=3, plan_particles=40, p_void_min=0.0)
    res = solve_straight(p)
    assert res.status is Status.FEASIBLE and res.plan is not None and res.bound is None
    poses = np.vstack([POSE, res.plan.path])
    for j in range(3):
        want = straight_sweep_heading(p.scenario.uav, poses[5 * j], p.scenario.area_m)
        assert res.plan.headings[j] == pytest.approx(want)
    assert res.objective == pytest.approx(float(np.sum(res.plan.rewards)))
    best = solve_exhaustive(p)
    assert best.objective is not None and res.objective <= best.objective


def test_backend_relations() -> None:
    """greedy ≤ beam ≤ exhaustive; greedy with H = 1 and a wide beam are OPTIMAL; the
    exhaustive search started from beam's plan gives the same optimum."""
    p = problem(spread_belief(3), horizon=3, plan_particles=30)
    ex, beam, greedy = solve_exhaustive(p), solve_beam(p, width=2), solve_greedy(p)
    values = [r.objective for r in (greedy, beam, ex)]
    assert all(v is not None for v in values)
    assert values[0] <= values[1] + 1e-12 and values[1] <= values[2] + 1e-12  # type: ignore
    assert ex.status is Status.OPTIMAL and beam.status is Status.FEASIBLE
    wide = solve_beam(p, width=16)
    assert wide.status is Status.OPTIMAL and wide.objective == pytest.approx(ex.objective)
    warm = solve_exhaustive(p, initial=beam.plan)
    assert warm.status is Status.OPTIMAL and warm.objective == pytest.approx(ex.objective)
    one = problem(spread_belief(3), horizon=1, plan_particles=30)
    assert solve_greedy(one).status is Status.OPTIMAL
    assert solve_greedy(one).objective == pytest.approx(solve_exhaustive(one).objective)


def test_bad_width() -> None:
    """A beam width below 1 is refused."""
    with pytest.raises(InvalidInputError, match="width"):
        solve_beam(problem(), width=0)


def test_too_close_already_leaves_the_soonest() -> None:
    """The UAV is 20 m behind a certain, tight tag: every sequence breaks the constraint in its
    first second, so the smallest void ties them all; the least total violation turns away
    (where reward alone would hover over the tag), and beam agrees."""
    b = tag_ahead()
    b.x[0, :, 0] += POSE[0] + 20.0 - 700.0
    b.x[0, :, 2] += POSE[1] - 600.0
    p = problem(b, horizon=2, plan_particles=60)
    res = solve_exhaustive(p)
    assert res.plan is not None and not res.plan.feasible
    least = min(plan.violation(0.9) for _, _, plan in every_sequence(Scorer(p, 0)))
    assert res.plan.violation(0.9) == pytest.approx(least, rel=1e-12)
    first = res.plan.path[4, :2]                      # after the first interval
    assert np.hypot(*(first - POSE[:2])) > 60.0
    assert np.hypot(first[0] - (POSE[0] + 20.0), first[1] - POSE[1]) > 50.0
    beam = solve_beam(p)
    assert beam.plan is not None and beam.plan.violation(0.9) == pytest.approx(least, rel=1e-9)


@pytest.mark.parametrize(("reward", "alpha"), [("renyi", 0.5), ("cs", 0.5), ("renyi", 1.0)])
def test_exploration_draws_the_uav_to_a_tag_not_heard(reward: str, alpha: float) -> None:
    """Every label at about r_B, one of them (label 0) 450 m ahead: the paper's reward is next
    to nothing whichever way the UAV flies; with exploration, flying toward the cloud earns
    more than flying away, and the plan heads for it (the short-range calibration: at the
    default one the whole cloud is heard from either way)."""
    b = belief([[1050.0, 600.0], [100.0, 100.0], [100.0, 1400.0], [1400.0, 1400.0]],
               [1e-6] * 4, spread_m=60.0)
    paper = 0.0
    for explore in (0.0, 0.5):
        p = problem(b, horizon=1, plan_particles=150, reward=reward, alpha=alpha,
                    p_void_min=0.0, explore_existence=explore, calibration="unscaled")
        rewards = {seq[0]: plan.rewards[0] for seq, _, plan in every_sequence(Scorer(p, 0))}
        toward, away = rewards[2], rewards[0]  # Δ = 0 and Δ = −π from heading east
        if explore == 0.0:
            paper = max(rewards.values())
            assert paper < 1e-5
            continue
        assert toward > 2.0 * away > 1e4 * paper
        res = solve_exhaustive(p)
        assert res.plan is not None and math.cos(res.plan.headings[0]) > 0.5
