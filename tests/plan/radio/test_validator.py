"""The independent check: every backend's plan is flyable, its void probabilities and rewards
are recomputed by brute force, and tampered plans are caught."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from searchtrack.core.result import Status
from searchtrack.models.radio import fly_heading
from searchtrack.plan.radio import RadioPlan, RadioPlanProblem, check_plan, solve
from searchtrack.plan.radio.validator import answer_problems

from .helpers import POSE, belief, problem, spread_belief, surrounded, tag_ahead

BACKENDS = ["exhaustive", "beam", "greedy", "straight", "auto"]


@pytest.mark.parametrize(("explore", "inflation"), [(0.0, 0.0), (0.5, 0.0), (0.3, 1.5)])
@pytest.mark.parametrize("reward", ["renyi", "cs"])
@pytest.mark.parametrize("backend", BACKENDS)
def test_every_backend_plan_checks(backend: str, reward: str, explore: float,
                                   inflation: float) -> None:
    """Valid kinematics; void equal to the planner's; rewards equal to the exact-likelihood
    recomputation (rel. 1e-6); the constraint verdict and the objective agree — with and
    without exploration (label 2 not heard: r = 1e-4) and spread-inflated keep-out discs."""
    b = tag_ahead()
    b.r[2] = 1e-4
    p = problem(b, horizon=2, plan_particles=40, reward=reward, alpha=0.7,
                explore_existence=explore, spread_inflation=inflation)
    res = solve(p, backend=backend, seed=7, time_limit_s=30.0)
    assert res.plan is not None
    check = check_plan(p, res.plan, seed=7, any_heading=backend == "straight")
    assert check.valid, check.reasons
    assert np.allclose(check.void, res.plan.void, rtol=0.0, atol=1e-12)
    assert check.meets_constraint == res.plan.feasible
    assert np.allclose(check.rewards, res.plan.rewards, rtol=1e-6, atol=1e-12)
    if res.plan.feasible:
        assert res.objective == pytest.approx(check.objective, rel=1e-6)
    else:
        assert res.objective is None and res.fallback is res.plan


def test_least_violating_plan_checks() -> None:
    """The least-violating plan is flyable and its recomputed constraint fails as reported."""
    p = problem(surrounded(), horizon=2, plan_particles=40)
    res = solve(p, backend="exhaustive")
    assert res.status is Status.INFEASIBLE and res.plan is not None
    check = check_plan(p, res.plan)
    assert check.valid and not check.meets_constraint
    assert check.void.min() == pytest.approx(res.plan.min_void, abs=1e-12)


def _tampered(plan: RadioPlan, **change: np.ndarray) -> RadioPlan:
    arrays = {"headings": plan.headings, "path": plan.path, "rewards": plan.rewards,
              "void": plan.void}
    arrays.update(change)
    return RadioPlan(arrays["headings"], arrays["path"], arrays["rewards"], arrays["void"],
                     plan.feasible)


def _plan(p: RadioPlanProblem) -> RadioPlan:
    res = solve(p, backend="greedy")
    assert res.plan is not None
    return res.plan


def test_faults_are_named() -> None:
    """A moved pose, an over-sharp turn, a heading that is no primitive, a wrong length."""
    p = problem(spread_belief(), horizon=2, plan_particles=30)
    plan = _plan(p)
    path = plan.path.copy()
    path[3, :2] += 5.0
    assert any("moves" in r for r in check_plan(p, _tampered(plan, path=path)).reasons)
    path = plan.path.copy()
    path[6, 2] += 1.5
    reasons = check_plan(p, _tampered(plan, path=path)).reasons
    assert any("more than" in r for r in reasons) and not check_plan(p, _tampered(
        plan, path=path)).valid
    heads = plan.headings.copy()
    heads[1] += 0.3
    assert any("not a primitive" in r for r in check_plan(p, _tampered(plan,
                                                                       headings=heads)).reasons)
    short = RadioPlan(plan.headings[:1], plan.path[:5], plan.rewards[:1], plan.void[:5], True)
    bad = check_plan(p, short)
    assert not bad.valid and "horizon" in bad.reasons[0] and math.isnan(bad.objective)


def test_leaving_the_area_is_a_fault() -> None:
    """Flying west from near the west edge is flyable but leaves the area: flagged; the
    planner's own plan from there stays inside."""
    pose = np.array([20.0, 750.0, math.pi])
    p = problem(spread_belief(), pose, horizon=1, plan_particles=30, n_headings=8)
    assert check_plan(p, _plan(p)).valid
    west = fly_heading(p.scenario.uav, pose, math.pi, 5.0)
    plan = RadioPlan(np.array([math.pi]), west, np.zeros(1), np.ones(5), True)
    check = check_plan(p, plan)
    # the first pose lies on the edge x = 0, which belongs to the area
    assert not check.valid and check.reasons == (
        "interval 0: 4 poses outside the area, though a heading kept it inside",)


def test_leaving_the_area_when_it_must_is_not_a_fault() -> None:
    """From just outside the west edge, heading out, every primitive leaves the area: the
    planner accepts the pose, flies the primitive that ends nearest to the area, and the
    validator does not flag what no heading could avoid."""
    pose = np.array([-5.0, 750.0, math.pi])
    p = problem(spread_belief(), pose, horizon=1, plan_particles=30, n_headings=8)
    plan = _plan(p)
    assert check_plan(p, plan).valid
    west = fly_heading(p.scenario.uav, pose, math.pi, 5.0)
    assert plan.path[-1, 0] > west[-1, 0] + 50.0


def test_solve_rejects_a_tampered_answer() -> None:
    """The registry's validator recomputes the plan on the solve's seed: every backend's answer
    stands, a reward changed after the fact turns the answer into ERROR."""
    import dataclasses

    from searchtrack.plan.radio.solve import BACKENDS as RADIO_BACKENDS
    from searchtrack.plan.radio.validator import answer_problems

    p = problem(tag_ahead(), horizon=2, plan_particles=40)
    for backend in BACKENDS:
        res = solve(p, backend=backend, seed=3, time_limit_s=30.0)
        assert res.status is not Status.ERROR, res.message
        assert res.plan is not None and answer_problems(p, res, seed=3) == []
    res = solve(p, backend="greedy", seed=3)
    assert res.plan is not None
    lie = dataclasses.replace(res, plan=_tampered(res.plan, rewards=res.plan.rewards * 1.01))
    assert any("rewards" in r for r in answer_problems(p, lie, seed=3))
    assert RADIO_BACKENDS.validated(p, lie, seed=3).status is Status.ERROR


def test_rewards_without_the_exploration_term_are_caught() -> None:
    """A plan scored with exploration does not check against the paper's reward, and back:
    the validator reads explore_existence on its own."""
    b = tag_ahead()
    b.r[2] = 1e-4
    explored = problem(b, horizon=2, plan_particles=40, explore_existence=0.5)
    paper = problem(b, horizon=2, plan_particles=40, explore_existence=0.0)
    res = solve(explored, backend="exhaustive", seed=7, time_limit_s=30.0)
    assert res.plan is not None and res.status is not Status.ERROR
    assert np.allclose(check_plan(explored, res.plan, seed=7).rewards, res.plan.rewards,
                       rtol=1e-6)
    assert not np.allclose(check_plan(paper, res.plan, seed=7).rewards, res.plan.rewards,
                           rtol=1e-6)


@pytest.mark.parametrize("alpha", [0.5, 1.0, 2.0])
def test_certain_and_impossible_labels_check_at_every_alpha(alpha: float) -> None:
    """Existences of exactly 1 and 0 (label sets of weight 0) are checked at every Rényi α,
    including α > 1, where a weight of 0 would be raised to a negative power."""
    from .helpers import belief

    b = belief([[700.0, 600.0], [500.0, 900.0], [300.0, 400.0], [1000.0, 1100.0]],
               [1.0, 0.0, 0.6, 1.0])
    p = problem(b, reward="renyi", alpha=alpha)
    result = solve(p, backend="exhaustive", time_limit_s=30.0)
    assert result.plan is not None and result.status is Status.OPTIMAL
    check = check_plan(p, result.plan)
    assert check.valid and check.reasons == ()
    assert math.isfinite(check.objective) and check.objective == pytest.approx(result.objective)


def test_updates_keep_particles_whose_weight_underflows() -> None:
    """A particle 800 nats behind after one update wins after a second 1000 nats in its favour:
    the validator's chain keeps log weights, as the planner's does (linear weights would have
    lost it to underflow and scored the plan differently)."""
    from searchtrack.plan.radio.validator import _log_update

    log_w = np.log(np.full((1, 2), 0.5))
    r = np.array([0.9])
    log_w, r1 = _log_update(log_w, r, np.array([[0.0, -800.0]]))
    assert np.exp(log_w[0, 1]) == 0.0 and log_w[0, 1] > -801.0
    log_w, r2 = _log_update(log_w, r1, np.array([[0.0, 1000.0]]))
    np.testing.assert_allclose(np.exp(log_w[0]), [math.exp(-200.0), 1.0], rtol=1e-12)
    eta = 0.5 * (1.0 + math.exp(-800.0))  # the first update's η: r barely moves
    assert r1[0] == pytest.approx(0.9 * eta / (0.1 + 0.9 * eta), rel=1e-12)
    assert r2[0] == pytest.approx(1.0, abs=1e-12)
    assert _log_update(log_w, np.array([0.0]), np.zeros((1, 2)))[1][0] == 0.0
    assert _log_update(log_w, np.array([1.0]), np.zeros((1, 2)))[1][0] == 1.0


@pytest.mark.parametrize("backend", BACKENDS)
def test_without_the_constraint_a_void_of_zero_is_feasible(backend: str) -> None:
    """``P_vmin = 0`` is no constraint: with a certain object under the UAV (void probability 0
    up to rounding, which the planner and the validator round differently) every backend's
    plan is feasible, the validator agrees and finds nothing wrong."""
    b = belief([POSE[:2].tolist(), [1300.0, 200.0], [200.0, 1300.0], [1300.0, 1300.0]],
               [1.0, 0.8, 0.8, 0.8], spread_m=1.0)
    p = problem(b, horizon=2, plan_particles=40, p_void_min=0.0)
    res = solve(p, backend=backend, seed=3, time_limit_s=30.0)
    assert res.plan is not None and res.plan.feasible and res.status is not Status.INFEASIBLE
    assert res.plan.min_void < 1e-9
    check = check_plan(p, res.plan, seed=3, any_heading=backend == "straight")
    assert check.valid and check.meets_constraint
    assert answer_problems(p, res, seed=3) == []


def test_a_void_at_the_bound_is_a_tie_the_validator_lets_pass() -> None:
    """A plan whose void probability equals ``P_vmin`` up to rounding may be called feasible
    or not; a verdict that disagrees with voids clearly on one side is caught."""
    b = belief([POSE[:2].tolist(), [1300.0, 200.0], [200.0, 1300.0], [1300.0, 1300.0]],
               [1.0, 0.8, 0.8, 0.8], spread_m=1.0)
    p = problem(b, horizon=2, plan_particles=40, p_void_min=0.5)
    res = solve(p, backend="exhaustive", seed=3)
    assert res.plan is not None and not res.plan.feasible
    plan = res.plan
    flipped = dataclasses.replace(
        res, plan=RadioPlan(plan.headings, plan.path, plan.rewards, plan.void, True))
    assert any("feasible" in s for s in answer_problems(p, flipped, seed=3))
    tied = dataclasses.replace(p, settings=dataclasses.replace(
        p.settings, p_void_min=max(0.0, float(plan.min_void)) + 1e-12))
    assert not any("feasible" in s for s in answer_problems(tied, flipped, seed=3))
