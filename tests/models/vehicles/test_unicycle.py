"""Unicycle / Dubins car (001 eq. 5.1): dynamics by hand, circles and lines, limits, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import unicycle


def test_unicycle_wind_drifts_and_turns_at_the_commanded_rate() -> None:
    """Unicycle: wind adds to the velocity and the heading changes by ω·t."""
    model = unicycle()
    x = model.step([0.0, 0.0, 0.0], [10.0, 0.5], 2.0, [1.0, -2.0], substeps=200)
    assert x[2] == pytest.approx(1.0)
    radius = 10.0 / 0.5
    assert x[0] == pytest.approx(radius * math.sin(1.0) + 2.0, abs=1e-8)
    assert x[1] == pytest.approx(radius * (1 - math.cos(1.0)) - 4.0, abs=1e-8)


def test_dynamics_by_hand() -> None:
    """ẋ = v cos θ + w_x, ẏ = v sin θ + w_y, θ̇ = ω at θ = π/3."""
    xdot = unicycle().f([1.0, 2.0, math.pi / 3], [10.0, 0.2], [0.5, -0.5])
    np.testing.assert_allclose(xdot, [5.5, 10.0 * math.sqrt(3) / 2 - 0.5, 0.2], atol=1e-12)


def test_straight_line_is_exact() -> None:
    """Without turning, one RK4 step moves exactly v·t along the heading."""
    x = unicycle().step([0.0, 0.0, math.pi / 4], [10.0, 0.0], 3.0)
    np.testing.assert_allclose(x, [15 * math.sqrt(2), 15 * math.sqrt(2), math.pi / 4],
                               atol=1e-12)


def test_limits_and_cruise() -> None:
    """Defaults: v ∈ [5, 15], |ω| ≤ 1, cruise at mid speed; a Dubins car has v_min = v_max."""
    model = unicycle()
    assert (model.nx, model.nu, model.n_wind) == (3, 2, 2)
    assert model.input_lower == (5.0, -1.0) and model.input_upper == (15.0, 1.0)
    assert model.input_rate_max == (5.0, 4.0)
    assert model.nominal_input == (10.0, 0.0)
    assert model.angle_indices == (2,) and model.position_indices == (0, 1)
    assert unicycle(cruise_speed_mps=12.0).nominal_input == (12.0, 0.0)
    dubins = unicycle(speed_min_mps=9.0, speed_max_mps=9.0)
    assert dubins.input_lower[0] == dubins.input_upper[0] == dubins.nominal_input[0] == 9.0


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"speed_min_mps": -1.0}, "speed_min_mps"),
    ({"speed_max_mps": 0.0}, "speed_max_mps"),
    ({"turn_rate_max_rps": 0.0}, "turn_rate_max_rps"),
    ({"accel_max_mps2": math.inf}, "accel_max_mps2"),
    ({"turn_accel_max_rps2": -4.0}, "turn_accel_max_rps2"),
    ({"cruise_speed_mps": 16.0}, "cruise_speed_mps"),
])
def test_bad_limits_name_the_field(kwargs: dict[str, float], field: str) -> None:
    """Each bad limit raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        unicycle(**kwargs)
    assert err.value.field == field
