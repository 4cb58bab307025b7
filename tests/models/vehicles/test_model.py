"""VehicleModel and rk4_step: the RK4 polynomial, stepping, clipping, checks and validation."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import (
    NUMPY,
    ArrayNamespace,
    VehicleModel,
    rk4_step,
    uav7,
    unicycle,
)
from searchtrack.models.vehicles.unicycle import UnicycleDynamics


@dataclass(frozen=True)
class Decay:
    """``ẋ = λ x`` (input and wind ignored)."""

    rate: float

    def __call__(self, x: Any, u: Any, p: Any, ns: ArrayNamespace) -> Any:
        """``λ x``."""
        return self.rate * x


#: A planar unicycle with a 1 × 1 m state box; fields are replaced one at a time below.
BASE: dict[str, Any] = {
    "name": "box", "state_names": ("x", "y", "t"), "input_names": ("v", "w"),
    "dynamics": UnicycleDynamics(), "state_lower": (0.0, 0.0, -math.inf),
    "state_upper": (1.0, 1.0, math.inf), "input_lower": (0.0, -1.0), "input_upper": (2.0, 1.0),
    "input_rate_max": (1.0, math.inf), "nominal_input": (1.0, 0.0), "position_indices": (0, 1),
    "angle_indices": (2,),
}


def test_rk4_step_is_the_fourth_order_taylor_polynomial() -> None:
    """For ẋ = λx one RK4 step multiplies x by 1 + z + z²/2 + z³/6 + z⁴/24 with z = λ h."""
    z = -0.3 * 0.5
    x1 = rk4_step(Decay(-0.3), np.array([2.0, -4.0]), None, None, 0.5, NUMPY)
    np.testing.assert_allclose(x1, np.array([2.0, -4.0]) * (1 + z + z**2 / 2 + z**3 / 6
                                                            + z**4 / 24), rtol=1e-15)


def test_substeps_are_repeated_steps() -> None:
    """step(dt, substeps=n) equals n steps of dt/n: for ẋ = λx, x₀ R(λ dt/n)ⁿ."""
    model = VehicleModel(**{**BASE, "dynamics": Decay(-2.0), "state_lower": (-math.inf,) * 3,
                            "state_upper": (math.inf,) * 3})
    x0 = np.array([1.0, 2.0, 3.0])
    by_hand = x0
    for _ in range(4):
        by_hand = model.step(by_hand, model.nominal_input, 0.25)
    np.testing.assert_allclose(model.step(x0, model.nominal_input, 1.0, substeps=4), by_hand)
    z = -2.0 * 0.25
    np.testing.assert_allclose(by_hand, x0 * (1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24) ** 4,
                               rtol=1e-14)


def test_f_without_wind_is_f_with_zero_wind() -> None:
    """Leaving out the wind means no wind."""
    model = uav7()
    x = [0.0, 0.0, -10.0, 12.0, 0.4, 0.1, 0.2]
    np.testing.assert_array_equal(model.f(x, model.nominal_input),
                                  model.f(x, model.nominal_input, [0.0, 0.0, 0.0]))


def test_sizes_clip_and_position() -> None:
    """nx, nu and n_wind count names and position axes; clip_input and position pick entries."""
    model = VehicleModel(**BASE)
    assert (model.nx, model.nu, model.n_wind) == (3, 2, 2)
    np.testing.assert_array_equal(model.clip_input([3.0, -1.5]), [2.0, -1.0])
    np.testing.assert_array_equal(model.clip_input([1.5, 0.25]), [1.5, 0.25])
    np.testing.assert_array_equal(model.position([0.1, 0.2, 3.0]), [0.1, 0.2])
    batch = np.arange(12.0).reshape(3, 4)
    np.testing.assert_array_equal(model.position(batch), batch[:2])
    assert uav7().position(np.arange(7.0)).tolist() == [0.0, 1.0, 2.0]


def test_check_state_and_input() -> None:
    """check_state and check_input return read-only arrays inside the boxes and refuse the rest."""
    model = VehicleModel(**BASE)
    x = model.check_state("x0", [0.5, 1.0, 100.0])
    assert x.tolist() == [0.5, 1.0, 100.0] and not x.flags.writeable
    u = model.check_input("u0", [2.0 + 1e-12, -1.0])  # within the 1e-9 slack
    assert not u.flags.writeable
    with pytest.raises(InvalidInputError, match=r"x0=.*outside the state bounds in \['y'\]"):
        model.check_state("x0", [0.5, 1.5, 0.0])
    with pytest.raises(InvalidInputError, match="x0"):
        model.check_state("x0", [0.5, 0.5])
    with pytest.raises(InvalidInputError, match=r"u0=.*outside the input bounds"):
        model.check_input("u0", [2.1, 0.0])
    with pytest.raises(InvalidInputError, match="u0"):
        model.check_input("u0", [math.inf, 0.0])


def test_step_refuses_bad_step_sizes() -> None:
    """A non-positive or NaN dt_s and fewer than one substep are named."""
    model = unicycle()
    for dt in (0.0, -0.1, math.nan):
        with pytest.raises(InvalidInputError, match="dt_s"):
            model.step([0.0, 0.0, 0.0], model.nominal_input, dt)
    with pytest.raises(InvalidInputError, match="substeps"):
        model.step([0.0, 0.0, 0.0], model.nominal_input, 0.1, substeps=0)


@pytest.mark.parametrize(("field", "value", "named"), [
    ("state_names", (), "state_names"),
    ("input_names", (), "state_names"),
    ("state_lower", (0.0, math.nan, 0.0), "state_lower"),
    ("state_upper", (1.0, 1.0), "state_upper"),
    ("state_upper", (1.0, -1.0, 1.0), "state_lower"),
    ("input_upper", (2.0, -2.0), "input_lower"),
    ("input_rate_max", (1.0, 0.0), "input_rate_max"),
    ("nominal_input", (3.0, 0.0), "nominal_input"),
    ("nominal_input", (1.0,), "nominal_input"),
    ("position_indices", (0,), "position_indices"),
    ("position_indices", (0, 3), "position_indices"),
    ("angle_indices", (3,), "angle_indices"),
])
def test_constructor_names_the_bad_field(field: str, value: tuple[Any, ...], named: str) -> None:
    """Empty names, ragged or NaN bounds, inverted boxes, zero rates and bad indices are named."""
    with pytest.raises(InvalidInputError) as err:
        VehicleModel(**{**BASE, field: value})
    assert err.value.field == named
