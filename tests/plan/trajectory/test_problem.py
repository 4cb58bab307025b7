"""Tracking problems and plans: validation by field, stage references, guesses and projection."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import fixed_wing
from searchtrack.plan.trajectory import (
    ControlPlan,
    TrackingProblem,
    TrackingWeights,
    waypoint_path,
)
from searchtrack.plan.trajectory.problem import initial_guess, project_inputs
from tests.plan.trajectory.plans import small_problem


def test_infeasible_starts_and_bad_fields_are_rejected() -> None:
    """A start inside an obstacle, NaN, bad horizon, rates and reference sizes name the field."""
    with pytest.raises(InvalidInputError, match="inside obstacle 0"):
        small_problem(state=np.array([21.0, 0.0, 0.0]))
    with pytest.raises(InvalidInputError, match="state"):
        small_problem(state=np.array([math.nan, 0.0, 0.0]))
    with pytest.raises(InvalidInputError, match="horizon"):
        small_problem(horizon=-3)
    with pytest.raises(InvalidInputError, match="dt_s"):
        small_problem(dt_s=0.0)
    with pytest.raises(InvalidInputError, match="previous_input"):
        small_problem(previous_input=np.array([100.0, 0.0]))
    with pytest.raises(InvalidInputError, match="reference"):
        small_problem(reference=waypoint_path([[0, 0, 0], [1, 0, 0]], 1.0))
    with pytest.raises(InvalidInputError, match="pitch_rad"):
        TrackingProblem(fixed_wing(), np.array([0, 0, 10, 0, 1.2]),
                        waypoint_path([[0, 0, 10], [1, 0, 10]], 1.0))
    with pytest.raises(InvalidInputError, match="z_m"):
        TrackingProblem(fixed_wing(), np.array([0, 0, 80, 0, 0.0]),
                        waypoint_path([[0, 0, 10], [1, 0, 10]], 1.0))


def test_weights_reject_negative_values() -> None:
    """TrackingWeights rejects out-of-domain values by name."""
    with pytest.raises(InvalidInputError, match="effort"):
        TrackingWeights(effort=-0.1)


@pytest.mark.parametrize("name", ["position", "terminal", "effort", "rate"])
def test_each_weight_is_checked(name: str) -> None:
    """Every weight must be finite and ≥ 0 (0 switches a term off)."""
    assert getattr(TrackingWeights(**{name: 0.0}), name) == 0.0
    for bad in (-1.0, math.nan, math.inf):
        with pytest.raises(InvalidInputError) as info:
            TrackingWeights(**{name: bad})
        assert info.value.field == name


@pytest.mark.parametrize(("changes", "field"), [
    ({"wind_mps": np.zeros(3)}, "wind_mps"), ({"wind_mps": np.array([math.nan, 0.0])}, "wind_mps"),
    ({"safety_margin_m": -0.5}, "safety_margin_m"), ({"time_s": math.inf}, "time_s"),
    ({"horizon": 2.5}, "horizon"), ({"previous_input": np.array([10.0])}, "previous_input")])
def test_more_bad_fields_are_named(changes: dict[str, object], field: str) -> None:
    """A wind of the wrong size or NaN, a negative margin, an infinite time, a fractional
    horizon and a short previous input each name their field."""
    with pytest.raises(InvalidInputError) as info:
        small_problem(**changes)
    assert info.value.field == field


def test_a_warm_plan_for_another_model_is_refused() -> None:
    """A warm plan whose input or state width differs from the model's names ``warm``."""
    plan = ControlPlan(inputs=np.zeros((2, 3)), states=np.zeros((3, 5)), dt_s=0.1,
                       controller="nmpc")
    with pytest.raises(InvalidInputError) as info:
        small_problem(warm=plan)
    assert info.value.field == "warm"


def test_defaults_are_filled_and_read_only() -> None:
    """Without them, the previous input is the nominal one and the wind zero; both are frozen."""
    problem = small_problem()
    np.testing.assert_array_equal(problem.u_prev, [10.0, 0.0])
    np.testing.assert_array_equal(problem.wind, [0.0, 0.0])
    with pytest.raises(ValueError):
        problem.state[0] = 1.0


def test_stage_references_start_one_step_ahead() -> None:
    """Stage k tracks r(time_s + k dt_s), k = 1..N: at 10 m/s from t = 1 s with dt 0.5 s."""
    problem = small_problem(time_s=1.0, dt_s=0.5, horizon=3)
    np.testing.assert_allclose(problem.reference_positions(), [[15, 0], [20, 0], [25, 0]])


def test_input_range_is_the_box_width() -> None:
    """The effort normaliser is the width of each input box: 15 − 5 m/s and 2 · 1 rad/s."""
    np.testing.assert_allclose(small_problem().input_range(), [10.0, 2.0])


def test_plan_shapes_and_values_are_checked() -> None:
    """A plan needs N ≥ 1 inputs and N + 1 states, finite, with a positive stage length."""
    with pytest.raises(InvalidInputError, match="inputs"):
        ControlPlan(inputs=np.zeros((2, 2)), states=np.zeros((2, 3)), dt_s=0.1, controller="x")
    with pytest.raises(InvalidInputError, match="inputs"):
        ControlPlan(inputs=np.zeros((0, 2)), states=np.zeros((1, 3)), dt_s=0.1, controller="x")
    with pytest.raises(InvalidInputError, match="plans must be finite"):
        ControlPlan(inputs=np.array([[math.nan, 0.0]]), states=np.zeros((2, 3)), dt_s=0.1,
                    controller="x")
    with pytest.raises(InvalidInputError, match="dt_s"):
        ControlPlan(inputs=np.zeros((1, 2)), states=np.zeros((2, 3)), dt_s=0.0, controller="x")


def test_plan_is_read_only_and_gives_its_first_input() -> None:
    """The arrays of a plan cannot be written and ``first_input`` is row 0."""
    plan = ControlPlan(inputs=[[1.0, 2.0], [3.0, 4.0]], states=np.zeros((3, 3)), dt_s=0.1,
                       controller="x")  # type: ignore[arg-type]
    np.testing.assert_array_equal(plan.first_input, [1.0, 2.0])
    with pytest.raises(ValueError):
        plan.inputs[0, 0] = 9.0


def test_cold_guess_rolls_the_nominal_input_out_in_the_wind() -> None:
    """Without a warm plan the guess is u = (10, 0) held, carried 11 m/s east by a 1 m/s wind."""
    problem = small_problem(horizon=3, wind_mps=np.array([1.0, 0.0]))
    x, u = initial_guess(problem)
    np.testing.assert_allclose(u, np.tile([10.0, 0.0], (3, 1)))
    np.testing.assert_allclose(x, [[0, 0, 0], [1.1, 0, 0], [2.2, 0, 0], [3.3, 0, 0]], atol=1e-12)


def test_warm_guess_is_shifted_with_the_heading_unwrapped() -> None:
    """The warm plan moves up one stage (the last repeated), the first state is the problem's,
    and headings near 2π are moved by a whole turn to sit next to the state's heading 0."""
    warm = ControlPlan(inputs=np.array([[10.0, 0.0], [11.0, 0.1], [12.0, 0.2]]),
                       states=np.array([[0, 0, 0.0], [1, 0, 6.2], [2, 0, 6.3], [3, 0, 6.4]]),
                       dt_s=0.1, controller="nmpc")
    problem = small_problem(horizon=3, state=np.array([0.5, 0.0, 0.0]), warm=warm)
    x, u = initial_guess(problem)
    np.testing.assert_allclose(u, [[11.0, 0.1], [12.0, 0.2], [12.0, 0.2]])
    turn = 2.0 * math.pi
    np.testing.assert_allclose(x, [[0.5, 0, 0], [2, 0, 6.3 - turn], [3, 0, 6.4 - turn],
                                   [3, 0, 6.4 - turn]])


def test_warm_guess_inputs_are_clipped_into_the_box() -> None:
    """Warm inputs outside today's box (a faster model before) are clipped to it."""
    warm = ControlPlan(inputs=np.array([[10.0, 0.0], [20.0, -3.0]]), states=np.zeros((3, 3)),
                       dt_s=0.1, controller="nmpc")
    _, u = initial_guess(small_problem(horizon=2, warm=warm))
    np.testing.assert_allclose(u, [[15.0, -1.0], [15.0, -1.0]])


def test_projection_meets_rate_limits_then_the_box() -> None:
    """From (10, 0) with steps of at most (0.5 m/s, 0.4 rad/s) per 0.1 s, stage by stage."""
    problem = small_problem()
    out = project_inputs(problem, np.array([[12.0, 1.0], [12.0, -1.0], [3.0, 0.0]]))
    np.testing.assert_allclose(out, [[10.5, 0.4], [11.0, 0.0], [10.5, 0.0]])
    near_top = small_problem(previous_input=np.array([14.8, 0.9]))
    np.testing.assert_allclose(project_inputs(near_top, np.array([[20.0, 2.0]])), [[15.0, 1.0]])


def test_fixed_wing_problem_has_three_axes() -> None:
    """A 3-D model takes a 3-D reference and a three-component wind."""
    problem = TrackingProblem(fixed_wing(), np.array([0.0, 0.0, 10.0, 0.0, 0.0]),
                              waypoint_path([[0, 0, 10], [100, 0, 10]], 12.0),
                              wind_mps=np.array([1.0, 2.0, 0.0]), horizon=2, dt_s=1.0)
    np.testing.assert_allclose(problem.reference_positions(), [[12, 0, 10], [24, 0, 10]])
    np.testing.assert_array_equal(problem.wind, [1.0, 2.0, 0.0])
