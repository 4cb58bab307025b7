"""LTV-MPC: bounds and obstacle half-spaces, agreement with NMPC, rounds and the exact optimum."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.plan.trajectory import (
    ControlPlan,
    Obstacles,
    TrackingProblem,
    solve_ltv_mpc,
    solve_nmpc,
)
from tests.plan.trajectory.plans import check_limits, clearance, small_problem


def test_ltv_mpc_plan_respects_bounds_and_halfspaces(course: TrackingProblem) -> None:
    """The QP plan meets input and rate bounds and its positions keep the obstacle margin."""
    result = solve_ltv_mpc(course, time_limit_s=5.0)
    # FEASIBLE: the QP is solved to optimality, but only for the linearised problem
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert result.stats["qp_rounds"] == 3.0 and "after 3 round(s)" in result.message
    check_limits(course, result.plan)
    assert clearance(course, result.plan) >= course.safety_margin_m - 1e-3


def test_ltv_mpc_warm_start_agrees_with_nmpc(course: TrackingProblem) -> None:
    """Linearised about the NMPC plan, the QP's first input is close to NMPC's."""
    free = replace(course, obstacles=Obstacles())
    nmpc = solve_nmpc(free, time_limit_s=5.0)
    assert nmpc.plan is not None
    warm = ControlPlan(inputs=np.vstack([nmpc.plan.inputs[:1], nmpc.plan.inputs]),
                       states=np.vstack([nmpc.plan.states[:1], nmpc.plan.states]),
                       dt_s=free.dt_s, controller="nmpc")  # shifting it back gives the plan
    qp = solve_ltv_mpc(replace(free, warm=warm), time_limit_s=5.0, iterations=3)
    assert qp.plan is not None
    np.testing.assert_allclose(qp.plan.inputs[0], nmpc.plan.inputs[0], atol=0.05)


def test_on_the_reference_at_cruise_the_plan_is_cruise() -> None:
    """On a free line at its own speed the nominal rollout is exact and every cost term vanishes
    at u = (10 m/s, 0): the QP returns that input and the states along the line."""
    problem = small_problem(obstacles=Obstacles(), horizon=8)
    result = solve_ltv_mpc(problem, time_limit_s=5.0)
    assert result.status is Status.FEASIBLE and result.plan is not None
    np.testing.assert_allclose(result.plan.inputs, np.tile([10.0, 0.0], (8, 1)), atol=1e-3)
    expected = np.column_stack([np.arange(9) * 1.0, np.zeros(9), np.zeros(9)])
    np.testing.assert_allclose(result.plan.states, expected, atol=1e-2)
    assert result.stats["max_slack_m"] == 0.0 and result.plan.controller == "ltv_mpc"


@pytest.mark.parametrize(("iterations", "rounds"), [(1, 1.0), (2, 2.0), (None, 3.0)])
def test_cold_start_runs_the_asked_rounds(iterations: int | None, rounds: float) -> None:
    """``iterations`` linearise–solve rounds run (three by default on a cold start)."""
    free = small_problem(obstacles=Obstacles(), state=np.array([0.0, 2.0, 0.3]))
    result = solve_ltv_mpc(free, time_limit_s=5.0, iterations=iterations)
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert result.stats["qp_rounds"] == rounds
    assert f"after {int(rounds)} round(s)" in result.message


def test_one_round_through_an_obstacle_is_no_solution() -> None:
    """Linearised once about a rollout through the cylinder, the half-spaces point backwards,
    the slacks exceed the margin and the predicted collision is refused, not returned."""
    result = solve_ltv_mpc(small_problem(), time_limit_s=5.0, iterations=1)
    assert result.status is Status.NO_SOLUTION and result.plan is None
    assert "enters an obstacle" in result.message
    assert result.stats["max_slack_m"] > small_problem().safety_margin_m


def test_warm_start_takes_one_round() -> None:
    """With a warm plan the default is a single QP."""
    problem = small_problem()
    cold = solve_ltv_mpc(problem, time_limit_s=5.0)
    assert cold.plan is not None
    warm = solve_ltv_mpc(replace(problem, warm=cold.plan), time_limit_s=5.0)
    assert warm.stats["qp_rounds"] == 1.0 and warm.plan is not None
    check_limits(problem, warm.plan)


def test_obstacle_on_the_line_is_passed_at_the_margin() -> None:
    """A cylinder of 3 m on the line 12 m ahead: the plan keeps 3 m + 1 m margin from its
    centre (half-spaces are conservative), so it leaves the line."""
    problem = small_problem(obstacles=Obstacles(centers_m=[[12, 0.5]], radii_m=[3.0]),
                            horizon=20)
    result = solve_ltv_mpc(problem, time_limit_s=5.0)
    assert result.plan is not None
    pos = result.plan.states[1:, :2]
    assert np.min(np.linalg.norm(pos - [12.0, 0.5], axis=1)) >= 4.0 - 1e-3
    assert np.max(np.abs(pos[:, 1])) > 1.0


@pytest.mark.parametrize("limit", [0.0, -2.0, math.inf * 0])
def test_bad_time_limit_names_the_field(limit: float) -> None:
    """A non-positive or NaN time limit raises InvalidInputError naming time_limit_s."""
    with pytest.raises(InvalidInputError, match="time_limit_s"):
        solve_ltv_mpc(small_problem(), time_limit_s=limit)


def test_the_shifted_primal_moves_every_stage_block_one_stage_on() -> None:
    """States, inputs and obstacle slacks move one stage earlier, the last stage repeated."""
    from searchtrack.plan.trajectory.ltv_mpc import _layout, shifted_primal

    model, n, k = small_problem().model, 4, 2
    lay = _layout(model, n, k)
    nx, nu = model.nx, model.nu
    n_var = nx * (n + 1) + nu * n + n * k
    x = np.arange(n_var, dtype=float)
    sx = shifted_primal(lay, x)
    states, s_states = x[:nx * (n + 1)].reshape(n + 1, nx), sx[:nx * (n + 1)].reshape(n + 1, nx)
    assert np.array_equal(s_states[:-1], states[1:]) and np.array_equal(s_states[-1], states[-1])
    u0 = nx * (n + 1)
    inputs, s_inputs = x[u0:u0 + nu * n].reshape(n, nu), sx[u0:u0 + nu * n].reshape(n, nu)
    assert np.array_equal(s_inputs[:-1], inputs[1:]) and np.array_equal(s_inputs[-1], inputs[-1])
    slacks, s_slacks = x[u0 + nu * n:].reshape(n, k), sx[u0 + nu * n:].reshape(n, k)
    assert np.array_equal(s_slacks[:-1], slacks[1:]) and np.array_equal(s_slacks[-1], slacks[-1])
    assert np.array_equal(x, np.arange(n_var, dtype=float))   # the input is not changed


def test_a_warm_plan_that_would_enter_an_obstacle_gets_more_rounds() -> None:
    """A warm plan through the cylinder: one QP about it predicts a collision, so the warm
    start re-linearises and answers a plan that keeps the margin, instead of none."""
    from searchtrack.plan.trajectory.problem import initial_guess

    problem = small_problem(obstacles=Obstacles(centers_m=[[12.0, 0.3]], radii_m=[3.0]))
    states, inputs = initial_guess(problem)   # the nominal input rolled out: straight through
    through = ControlPlan(inputs=inputs, states=states, dt_s=problem.dt_s, controller="x")
    assert solve_ltv_mpc(replace(problem, warm=through), time_limit_s=5.0,
                         iterations=1).plan is None
    result = solve_ltv_mpc(replace(problem, warm=through), time_limit_s=5.0)
    assert result.plan is not None and 1.0 < result.stats["qp_rounds"] <= 3.0
    assert clearance(problem, result.plan) >= problem.safety_margin_m - 1e-3


def test_the_warm_start_saves_iterations_not_the_answer(course: TrackingProblem) -> None:
    """Along a receding-horizon run, each QP started from the warm plan's shifted solution ends
    where a cold OSQP start of the same QP ends (to OSQP's tolerance: no worse objective, the
    same first input), in fewer iterations over the run."""
    problem, iterations = course, np.zeros(2)
    for step in range(8):
        warm = solve_ltv_mpc(problem, time_limit_s=5.0)
        bare = None if problem.warm is None else replace(problem.warm, multipliers=None)
        cold = solve_ltv_mpc(replace(problem, warm=bare), time_limit_s=5.0)
        assert warm.plan is not None and cold.plan is not None
        assert warm.plan.multipliers is not None and cold.plan.multipliers is not None
        assert warm.objective is not None and cold.objective is not None
        assert warm.objective <= cold.objective + 1e-3 * abs(cold.objective)
        first = np.abs(warm.plan.first_input - cold.plan.first_input) / problem.input_range()
        assert first.max() <= 0.05
        if step:
            iterations += (warm.stats["qp_iterations"], cold.stats["qp_iterations"])
        x = problem.model.step(problem.state, warm.plan.first_input, problem.dt_s)
        problem = replace(problem, state=x, time_s=problem.time_s + problem.dt_s,
                          previous_input=warm.plan.first_input, warm=warm.plan)
    assert iterations[0] < iterations[1]


def test_an_answer_does_not_depend_on_earlier_calls(course: TrackingProblem) -> None:
    """The same problem gives the same plan (to rounding) whether or not another problem of its
    shape was solved in between (OSQP starts from the problem's own warm plan and its ρ)."""
    first = solve_ltv_mpc(course, time_limit_s=5.0)
    assert first.plan is not None
    follow = replace(course, state=first.plan.states[1], time_s=course.dt_s,
                     previous_input=first.plan.first_input, warm=first.plan)
    once = solve_ltv_mpc(follow, time_limit_s=5.0)
    solve_ltv_mpc(replace(course, state=np.array([5.0, 8.0, 1.0])), time_limit_s=5.0)
    again = solve_ltv_mpc(follow, time_limit_s=5.0)
    assert once.plan is not None and again.plan is not None
    assert np.allclose(once.plan.inputs, again.plan.inputs, rtol=0.0, atol=1e-9)
    assert once.stats["qp_iterations"] == again.stats["qp_iterations"]
