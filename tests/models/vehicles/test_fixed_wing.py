"""Fixed-wing kinematics of paper 003 §2.3: dynamics by hand, level circles, limits, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import fixed_wing


def test_dynamics_by_hand() -> None:
    """Heading north (ψ = π/2) pitched up π/6: ẏ = v cos θ, ż = v sin θ, plus the wind."""
    xdot = fixed_wing().f([0.0, 0.0, 10.0, math.pi / 2, math.pi / 6], [12.0, 0.1, -0.2],
                          [1.0, 2.0, 3.0])
    np.testing.assert_allclose(xdot, [1.0, 12.0 * math.sqrt(3) / 2 + 2.0, 9.0, 0.1, -0.2],
                               atol=1e-12)


def test_level_half_circle() -> None:
    """At θ = 0 a yaw rate ω flies a circle of radius v/ω: after π/ω s it is 2v/ω to the left."""
    model = fixed_wing()
    x = model.step([0.0, 0.0, 20.0, 0.0, 0.0], [12.0, 0.4, 0.0], math.pi / 0.4, substeps=200)
    np.testing.assert_allclose(x, [0.0, 60.0, 20.0, math.pi, 0.0], atol=1e-8)


def test_limits_and_cruise() -> None:
    """Defaults: 50 m ceiling, pitch within ±25°, v ∈ [8, 16], cruise level at 12 m/s."""
    model = fixed_wing()
    pitch = math.radians(25.0)
    assert (model.nx, model.nu, model.n_wind) == (5, 3, 3)
    assert model.state_lower == (-math.inf, -math.inf, 0.0, -math.inf, -pitch)
    assert model.state_upper == (math.inf, math.inf, 50.0, math.inf, pitch)
    assert model.input_lower == (8.0, -0.8, -0.5) and model.input_upper == (16.0, 0.8, 0.5)
    assert model.input_rate_max == (4.0, 3.0, 3.0)
    assert model.nominal_input == (12.0, 0.0, 0.0)
    assert model.position_indices == (0, 1, 2) and model.angle_indices == (3,)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"speed_min_mps": 0.0}, "speed_min_mps"),
    ({"speed_min_mps": 20.0}, "speed_min_mps"),
    ({"speed_max_mps": math.nan}, "speed_max_mps"),
    ({"pitch_max_rad": math.pi / 2}, "pitch_max_rad"),
    ({"pitch_max_rad": 0.0}, "pitch_max_rad"),
    ({"altitude_max_m": 0.0}, "altitude_max_m"),
    ({"yaw_rate_max_rps": 0.0}, "yaw_rate_max_rps"),
    ({"pitch_rate_max_rps": -0.5}, "pitch_rate_max_rps"),
    ({"accel_max_mps2": 0.0}, "accel_max_mps2"),
    ({"angular_accel_max_rps2": math.inf}, "angular_accel_max_rps2"),
])
def test_bad_limits_name_the_field(kwargs: dict[str, float], field: str) -> None:
    """Each bad limit raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        fixed_wing(**kwargs)
    assert err.value.field == field
