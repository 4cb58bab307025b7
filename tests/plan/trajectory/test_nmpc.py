"""NMPC: feasible plans, exact tracking where the answer is known, the solver cache and budgets."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.trajectory import NmpcOptions, Obstacles, TrackingProblem, solve_nmpc
from searchtrack.plan.trajectory.nmpc import build, prepare, wall_time_limit
from tests.plan.trajectory.plans import check_limits, clearance, small_problem


def test_nmpc_plan_is_feasible(course: TrackingProblem) -> None:
    """An NMPC plan obeys the RK4 dynamics, input and rate bounds and keeps the margin."""
    result = solve_nmpc(course, time_limit_s=5.0)
    assert result.status is Status.FEASIBLE and result.plan is not None
    plan = result.plan
    check_limits(course, plan)
    m = course.model
    for k in range(course.horizon):
        np.testing.assert_allclose(plan.states[k + 1], m.step(plan.states[k], plan.inputs[k],
                                                              course.dt_s), atol=1e-5)
    assert clearance(course, plan) >= course.safety_margin_m - 1e-4


def test_nmpc_tracks_a_straight_line_without_obstacles(course: TrackingProblem) -> None:
    """Started on a free straight reference at its speed, NMPC stays within 0.5 m of it."""
    problem = replace(course, state=np.array([0.0, 0.0, 0.0]), obstacles=Obstacles(),
                      previous_input=np.array([10.0, 0.0]))
    result = solve_nmpc(problem, time_limit_s=5.0)
    assert result.plan is not None
    err = result.plan.states[1:, :2] - problem.reference_positions()
    assert np.max(np.abs(err)) < 0.5


def test_unloadable_linear_solver_is_refused_when_the_solver_is_built() -> None:
    """A linear solver Ipopt cannot load (here: not a solver at all) is an InvalidInputError
    naming ``linear_solver`` at build time, not an Ipopt failure on every step."""
    from searchtrack.models.vehicles import unicycle
    from searchtrack.plan.trajectory import NmpcOptions, TrackingProblem, solve_nmpc, waypoint_path

    problem = TrackingProblem(unicycle(), np.array([0.0, -3.0, 0.0]),
                              waypoint_path([[0, 0], [50, 0]], 10.0), horizon=5)
    with pytest.raises(InvalidInputError, match="linear_solver"):
        solve_nmpc(problem, time_limit_s=1.0, options=NmpcOptions(linear_solver="no_such"))


def test_ipopt_wall_time_ladder() -> None:
    """Budgets round down to 1 ms · 1.25^k: never above the budget, at most 20 % below, and
    a handful of distinct solvers for many different budgets."""
    from searchtrack.plan.trajectory.nmpc import wall_time_limit

    budgets = np.linspace(0.001, 0.1, 500)
    limits = np.array([wall_time_limit(b) for b in budgets])
    assert np.all(limits <= budgets + 1e-12) and np.all(limits >= budgets / 1.25 - 1e-12)
    assert len(set(limits.round(12))) <= 21
    assert wall_time_limit(1e-5) == pytest.approx(1e-3)


@pytest.mark.parametrize(("budget_s", "expected_s"), [
    (1e-3, 1e-3), (1.25e-3, 1.25e-3), (1.3e-3, 1.25e-3), (0.05, 1e-3 * 1.25**17),
    (1.0, 1e-3 * 1.25**30)])
def test_wall_time_limit_hand_values(budget_s: float, expected_s: float) -> None:
    """The limit is the largest 1 ms · 1.25^k not above the budget (1.25^17 ms ≈ 44.4 ms ≤ 50 ms
    < 1.25^18 ms), exact on the rungs themselves."""
    assert wall_time_limit(budget_s) == pytest.approx(expected_s, rel=1e-12)


def test_on_the_reference_at_cruise_the_plan_is_cruise() -> None:
    """On a free line at its own speed every cost term vanishes at u = (10 m/s, 0): the plan is
    that input and the states run along the line at 10 m/s."""
    problem = small_problem(obstacles=Obstacles(), horizon=8)
    result = solve_nmpc(problem, time_limit_s=5.0)
    assert result.status is Status.FEASIBLE and result.plan is not None
    np.testing.assert_allclose(result.plan.inputs, np.tile([10.0, 0.0], (8, 1)), atol=1e-3)
    expected = np.column_stack([np.arange(9) * 1.0, np.zeros(9), np.zeros(9)])
    np.testing.assert_allclose(result.plan.states, expected, atol=1e-3)
    assert result.objective == pytest.approx(0.0, abs=1e-5)
    assert result.backend == "nmpc" and result.plan.controller == "nmpc"


def test_multipliers_have_the_nlp_layout_and_warm_start_the_next_solve() -> None:
    """A plan carries λ_x over (N+1)·nx + N·nu variables and λ_g over N·(nx + nu + obstacles)
    constraints; fed back as the warm plan, the next solve is feasible too."""
    problem = small_problem(horizon=6)
    first = solve_nmpc(problem, time_limit_s=5.0)
    assert first.plan is not None and first.plan.multipliers is not None
    lam_x, lam_g = first.plan.multipliers
    assert lam_x.shape == (7 * 3 + 6 * 2,) and lam_g.shape == (6 * (3 + 2 + 1),)
    nxt = replace(problem, state=first.plan.states[1], time_s=problem.dt_s,
                  previous_input=first.plan.inputs[0], warm=first.plan)
    second = solve_nmpc(nxt, time_limit_s=5.0)
    assert second.status is Status.FEASIBLE and second.plan is not None
    check_limits(nxt, second.plan)


def test_build_is_cached_per_shape_and_budget_rung() -> None:
    """The same shape and budget rung returns the same solver; another rung builds another."""
    problem = small_problem(horizon=4)
    a = prepare(problem, 0.05)
    assert prepare(problem, 0.046) is a  # 46 ms and 50 ms share the 44.4 ms rung
    assert build(problem.model, 4, 1, problem.dt_s, problem.weights, NmpcOptions(), 0.05) is a
    assert prepare(problem, 0.5) is not a
    assert a.horizon == 4 and a.n_obstacles == 1 and a.n_g == 4 * (3 + 2 + 1)


def test_problem_options_are_used_unless_overridden() -> None:
    """Without ``options`` the problem's ``nmpc_options`` decide (here an unloadable solver)."""
    problem = small_problem(horizon=3, nmpc_options=NmpcOptions(linear_solver="no_such"))
    with pytest.raises(InvalidInputError, match="linear_solver"):
        solve_nmpc(problem, time_limit_s=1.0)
    assert solve_nmpc(problem, time_limit_s=5.0, options=NmpcOptions()).plan is not None


@pytest.mark.parametrize("limit", [0.0, -1.0, math.nan])
def test_bad_time_limit_names_the_field(limit: float) -> None:
    """A non-positive or NaN time limit raises InvalidInputError naming time_limit_s."""
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve_nmpc(small_problem(), time_limit_s=limit)


@pytest.mark.parametrize("options", [NmpcOptions(solver="sqpmethod"),
                                     NmpcOptions(hessian="limited-memory", max_iter=200)])
def test_other_nlp_settings_solve_the_cruise_problem(options: NmpcOptions) -> None:
    """SQP (qrqp) and Ipopt's quasi-Newton Hessian also return the cruise input on the line."""
    problem = small_problem(obstacles=Obstacles(), horizon=5)
    result = solve_nmpc(problem, time_limit_s=10.0, options=options)
    assert result.status is Status.FEASIBLE and result.plan is not None, result.message
    np.testing.assert_allclose(result.plan.inputs, np.tile([10.0, 0.0], (5, 1)), atol=1e-3)
    assert options.solver in result.message
