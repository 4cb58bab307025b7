"""Closed-form laws: eq. (13) linearisation, eqs. (14)–(15) avoidance, pursuit and limits."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Status
from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle
from searchtrack.plan.trajectory import (
    ClosedFormGains,
    Obstacles,
    TrackingProblem,
    control_law,
    solve_closed_form,
    waypoint_path,
)
from tests.plan.trajectory.plans import check_limits, small_problem


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
    check_limits(course, result.plan)


def test_gains_reject_out_of_domain_values() -> None:
    """ClosedFormGains rejects out-of-domain values by name."""
    with pytest.raises(InvalidInputError, match="backstepping"):
        ClosedFormGains(backstepping=(1.0, 0.0, 1.0))
    with pytest.raises(InvalidInputError, match="obstacle_turn"):
        ClosedFormGains(obstacle_turn="left")  # type: ignore[arg-type]


@pytest.mark.parametrize(("changes", "field"), [
    ({"lookahead_s": 0.0}, "lookahead_s"), ({"heading_gain": -1.0}, "heading_gain"),
    ({"avoid_distance_m": math.nan}, "avoid_distance_m"), ({"avoid_gain": -0.1}, "avoid_gain"),
    ({"backstepping": (1.0, 2.0)}, "backstepping"), ({"roll_gain": math.inf}, "roll_gain")])
def test_each_bad_gain_names_its_field(changes: dict[str, object], field: str) -> None:
    """Every gain is checked (positive, finite; k_obs may be 0) and the error names it."""
    with pytest.raises(InvalidInputError) as info:
        ClosedFormGains(**changes)  # type: ignore[arg-type]
    assert info.value.field == field


def test_zero_avoid_gain_is_allowed() -> None:
    """k_obs = 0 switches the eq. (15) term off, which is a valid choice."""
    assert ClosedFormGains(avoid_gain=0.0).avoid_gain == 0.0


def test_pursuit_on_the_reference_holds_cruise() -> None:
    """On the line at its speed the target is straight ahead and the along-track error zero:
    u = (10 m/s, 0), and the rollout follows the line exactly with zero tracking error."""
    problem = small_problem(obstacles=Obstacles(), horizon=5)
    u = control_law(problem, problem.state, 0.0, problem.u_prev, ClosedFormGains())
    np.testing.assert_allclose(u, [10.0, 0.0])
    result = solve_closed_form(problem)
    assert result.plan is not None
    np.testing.assert_allclose(result.plan.inputs, np.tile([10.0, 0.0], (5, 1)))
    np.testing.assert_allclose(result.plan.states[:, 0], np.arange(6) * 1.0, atol=1e-12)
    assert result.objective == pytest.approx(0.0, abs=1e-20)


@pytest.mark.parametrize(("dt_s", "speed"), [(0.1, 10.5), (1.0, 11.0)])
def test_speed_loop_is_rate_limited(dt_s: float, speed: float) -> None:
    """2 m behind the reference point the speed loop asks 10 + 0.5 · 2 = 11 m/s; the 5 m/s²
    rate limit allows only 0.5 m/s more in a 0.1 s step, the whole 1 m/s in 1 s."""
    problem = small_problem(state=np.array([-2.0, 0.0, 0.0]), obstacles=Obstacles(), dt_s=dt_s)
    u = control_law(problem, problem.state, 0.0, np.array([10.0, 0.0]), ClosedFormGains())
    np.testing.assert_allclose(u, [speed, 0.0])


def test_heading_command_is_clipped_to_the_turn_rate_box() -> None:
    """Heading north with the target due east asks 2 · (−π/2) rad/s; the box allows −1 rad/s."""
    problem = small_problem(state=np.array([0.0, 0.0, math.pi / 2]), obstacles=Obstacles(),
                            dt_s=1.0)
    u = control_law(problem, problem.state, 0.0, np.array([10.0, 0.0]), ClosedFormGains())
    assert u[1] == pytest.approx(-1.0)


def test_repulsion_bends_the_heading_away_from_a_close_obstacle() -> None:
    """A cylinder just left of the line turns the pursuit command to the right (negative rate)."""
    free = small_problem(obstacles=Obstacles(), dt_s=1.0)
    near = small_problem(obstacles=Obstacles(centers_m=[[4.0, 3.0]], radii_m=[1.0]), dt_s=1.0)
    gains = ClosedFormGains()
    assert control_law(free, free.state, 0.0, free.u_prev, gains)[1] == pytest.approx(0.0)
    assert control_law(near, near.state, 0.0, near.u_prev, gains)[1] < -0.1


def test_fixed_wing_pitches_towards_a_higher_target() -> None:
    """The fixed wing gets three inputs; a target above it gives a positive pitch-rate input."""
    model = fixed_wing()
    ref = waypoint_path([[0, 0, 20], [100, 0, 40]], 12.0)
    problem = TrackingProblem(model, np.array([0.0, 0.0, 20.0, 0.0, 0.0]), ref, dt_s=1.0)
    u = control_law(problem, problem.state, 0.0, problem.u_prev, ClosedFormGains())
    assert u.shape == (3,) and u[2] > 0.0


def test_unknown_model_is_refused_by_name() -> None:
    """A model without a closed-form law raises InvalidInputError naming ``model``."""
    base = unicycle()
    other = VehicleModel("glider", base.state_names, base.input_names, base.dynamics,
                         base.state_lower, base.state_upper, base.input_lower, base.input_upper,
                         base.input_rate_max, base.nominal_input, base.position_indices)
    problem = small_problem(model=other)
    with pytest.raises(InvalidInputError) as info:
        solve_closed_form(problem)
    assert info.value.field == "model"


def test_objective_is_the_squared_tracking_error_of_the_rollout(course: TrackingProblem) -> None:
    """The reported objective is Σ‖p_k − r_k‖² over stages 1..N of the returned plan."""
    result = solve_closed_form(course)
    assert result.plan is not None and result.objective is not None
    err = result.plan.states[1:, :2] - course.reference_positions()
    assert result.objective == pytest.approx(float(np.sum(err**2)))
    assert result.objective > 1.0  # the course starts 3 m off the line
