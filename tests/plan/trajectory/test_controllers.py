"""NMPC, LTV-MPC and closed-form plans: bounds, rates, obstacle clearance and dynamics."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.models.vehicles import fixed_wing, uav7
from searchtrack.plan.trajectory import (
    ClosedFormGains,
    ControlPlan,
    Obstacles,
    TrackingProblem,
    control_law,
    solve_closed_form,
    solve_ltv_mpc,
    solve_nmpc,
    waypoint_path,
)

TOL = 1e-4


def _check_limits(problem: TrackingProblem, plan: ControlPlan) -> None:
    m = problem.model
    assert np.all(plan.inputs >= np.asarray(m.input_lower) - TOL)
    assert np.all(plan.inputs <= np.asarray(m.input_upper) + TOL)
    steps = np.diff(np.vstack([problem.u_prev, plan.inputs]), axis=0)
    assert np.all(np.abs(steps) <= np.asarray(m.input_rate_max) * problem.dt_s + TOL)
    np.testing.assert_allclose(plan.states[0], problem.state)


def _clearance(problem: TrackingProblem, plan: ControlPlan) -> float:
    pos = plan.states[1:, list(problem.model.position_indices)]
    return float(problem.obstacles.clearance_m(pos).min())


def test_nmpc_plan_is_feasible(course: TrackingProblem) -> None:
    """An NMPC plan obeys the RK4 dynamics, input and rate bounds and keeps the margin."""
    result = solve_nmpc(course, time_limit_s=5.0)
    assert result.status is Status.FEASIBLE and result.plan is not None
    plan = result.plan
    _check_limits(course, plan)
    m = course.model
    for k in range(course.horizon):
        np.testing.assert_allclose(plan.states[k + 1], m.step(plan.states[k], plan.inputs[k],
                                                              course.dt_s), atol=1e-5)
    assert _clearance(course, plan) >= course.safety_margin_m - 1e-4


def test_nmpc_tracks_a_straight_line_without_obstacles(course: TrackingProblem) -> None:
    """Started on a free straight reference at its speed, NMPC stays within 0.5 m of it."""
    problem = replace(course, state=np.array([0.0, 0.0, 0.0]), obstacles=Obstacles(),
                      previous_input=np.array([10.0, 0.0]))
    result = solve_nmpc(problem, time_limit_s=5.0)
    assert result.plan is not None
    err = result.plan.states[1:, :2] - problem.reference_positions()
    assert np.max(np.abs(err)) < 0.5


def test_ltv_mpc_plan_respects_bounds_and_halfspaces(course: TrackingProblem) -> None:
    """The QP plan meets input and rate bounds and its positions keep the obstacle margin."""
    result = solve_ltv_mpc(course, time_limit_s=5.0)
    # FEASIBLE: the QP is solved to optimality, but only for the linearised problem
    assert result.status is Status.FEASIBLE and result.plan is not None
    assert result.stats["qp_rounds"] == 3.0 and "after 3 round(s)" in result.message
    _check_limits(course, result.plan)
    assert _clearance(course, result.plan) >= course.safety_margin_m - 1e-3


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


@pytest.mark.parametrize("make", [fixed_wing, uav7])
def test_3d_models_get_feasible_plans(make: object) -> None:
    """Fixed-wing and 7-state UAV: NMPC and QP plans respect bounds and avoid a sphere."""
    model = make()  # type: ignore[operator]
    up = -1.0 if model.name == "uav7" else 1.0  # uav7 is NED
    state = np.zeros(model.nx)
    state[2] = 20.0 * up
    if model.name == "uav7":
        state[3] = 15.0
    ref = waypoint_path([[0, 0, 20 * up], [200, 0, 20 * up]], float(model.nominal_input[0])
                        if model.name != "uav7" else 15.0)
    problem = TrackingProblem(model, state, ref, obstacles=Obstacles(
        centers_m=[[15, 0.7, 20 * up]], radii_m=[3.0], cylinder=np.array([False])))
    for result in (solve_nmpc(problem, time_limit_s=5.0), solve_ltv_mpc(problem, time_limit_s=5.0)):
        assert result.plan is not None, result.message
        _check_limits(problem, result.plan)
        assert _clearance(problem, result.plan) >= problem.safety_margin_m - 1e-3


def _uav7_problem(**kw: object) -> TrackingProblem:
    model = uav7(thrust_min_n=-1e4, thrust_max_n=1e4, turn_input_max=1e4, load_factor_max=1e4,
                 roll_rate_max_rps=1e4, roll_max_rad=1.3, flight_path_max_rad=1.3)
    state = np.array([1.0, -2.0, -20.0, 15.0, 0.3, 0.05, 0.1])
    ref = waypoint_path([[0, 0, -20], [0, 0, -20.0001]], 1.0)
    return TrackingProblem(model, state, ref, previous_input=np.array(model.nominal_input),
                           **kw)  # type: ignore[arg-type]


def test_state_box_guard_keeps_the_uav7_inside_its_limits() -> None:
    """Behind a climbing, turning reference, the guarded law keeps airspeed and flight-path
    angle within the box on the true (unclipped) model; without the guard (a guard time too
    short to bind) the printed law leaves it."""
    model = uav7()
    ref = waypoint_path([[0, 0, -20], [40, 0, -20], [40, 40, -40], [0, 0, -20]], 15.0)
    problem = TrackingProblem(model, np.array([-60.0, -40.0, -10.0, 15.0, 0.0, 0.0, 0.0]), ref,
                              horizon=20, dt_s=0.1)
    lo, hi = np.asarray(model.state_lower), np.asarray(model.state_upper)

    def worst(gains: ClosedFormGains) -> tuple[float, float, float]:
        x, u = problem.state, np.asarray(model.nominal_input)
        rollout = [x]
        for k in range(150):
            u = control_law(problem, x, k * problem.dt_s, u, gains)
            x = model.step(x, u, problem.dt_s, problem.wind)
            rollout.append(x)
        states = np.array(rollout)
        return (float(states[:, 3].min()), float(states[:, 3].max()),
                float(np.abs(states[:, 5]).max()))

    va_lo, va_hi, gamma = worst(ClosedFormGains())
    assert va_lo >= lo[3] - 0.1 and va_hi <= hi[3] + 0.1 and gamma <= hi[5] + 0.01
    va_lo, va_hi, gamma = worst(ClosedFormGains(guard_time_s=1e-9))
    assert va_hi > hi[3] + 0.1 or gamma > hi[5] + 0.01
    with pytest.raises(InvalidInputError, match="guard_time_s"):
        ClosedFormGains(guard_time_s=0.0)


def test_backstepping_linearises_the_uav7_dynamics() -> None:
    """Eq. (13): unsaturated, q̈ = −(K1+K2+K3) q̇ − (1+K1K2K3)(q − q^d) for a fixed reference
    (the state-box guard is made too fast to bind)."""
    problem = _uav7_problem(dt_s=1.0)  # rate limits (per step) far from binding
    gains = ClosedFormGains(backstepping=(1.0, 2.0, 3.0), guard_time_s=1e-9)
    m, x = problem.model, problem.state
    u = control_law(problem, x, 0.0, np.zeros(4), gains)
    xdot = m.f(x, u)
    eps = 1e-7
    qdd = (m.f(x + eps * xdot, u)[:3] - m.f(x - eps * xdot, u)[:3]) / (2 * eps)
    ref = problem.reference.positions([0.0])[0]
    rdot = problem.reference.positions([1.0])[0] - ref
    expected = -6.0 * (xdot[:3] - rdot) - 7.0 * (x[:3] - ref)
    np.testing.assert_allclose(qdd, expected, rtol=1e-5, atol=1e-5)


def test_backstepping_obstacle_term_turns_away() -> None:
    """Eqs. (14)–(15): within d_l the heading input drops by k_obs, away from the obstacle side."""
    base = _uav7_problem(dt_s=1e-3)
    gains = ClosedFormGains()
    m, x = base.model, base.state
    free = control_law(base, x, 0.0, np.zeros(4), gains)
    right = x[:3] + 4.0 * np.array([math.cos(0.3 + 0.5), math.sin(0.3 + 0.5), 0.0])
    near = replace(base, obstacles=Obstacles(centers_m=[right], radii_m=[1.0]))
    turned = control_law(near, x, 0.0, np.zeros(4), gains)
    assert turned[1] == pytest.approx(free[1] - gains.avoid_gain)
    printed = control_law(near, x, 0.0, np.zeros(4), replace(gains, obstacle_turn="printed"))
    left = replace(base, obstacles=Obstacles(
        centers_m=[x[:3] + 4.0 * np.array([math.cos(0.3 - 0.5), math.sin(0.3 - 0.5), 0.0])],
        radii_m=[1.0]))
    assert control_law(left, x, 0.0, np.zeros(4), gains)[1] == pytest.approx(free[1] + 5.0)
    assert printed[1] == pytest.approx(free[1] - 5.0)
    assert m.name == "uav7"


def test_closed_form_rollout_respects_limits(course: TrackingProblem) -> None:
    """The closed-form rollout is FEASIBLE, within input and rate bounds."""
    result = solve_closed_form(course)
    assert result.status is Status.FEASIBLE and result.plan is not None
    _check_limits(course, result.plan)
