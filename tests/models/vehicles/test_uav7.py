"""The 7-state UAV of paper 004 eq. (12), errata fixed: rates by hand, lift, limits, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import GRAVITY_MPS2, uav7
from searchtrack.models.vehicles.uav7 import Uav7Dynamics
from tests.models.vehicles.catalogue import central_differences as _fd


def test_uav7_errata_make_the_decoupling_matrix_invertible_at_level_flight() -> None:
    """At γ = 0, ∂q̇/∂(V_a, β, γ) has det −V_a² (the printed sin β sin γ row would make it 0)."""
    model = uav7()
    x = np.array([0.0, 0.0, -20.0, 15.0, 0.3, 0.0, 0.0])
    jac = _fd(lambda z: model.f(np.concatenate([x[:3], z, x[6:]]), model.nominal_input)[:3],
              x[3:6])
    assert np.linalg.det(jac) == pytest.approx(-15.0**2, rel=1e-6)
    level = model.f(x, model.nominal_input)
    np.testing.assert_allclose(level[3:], 0.0, atol=1e-12)  # nominal input holds level cruise


def test_uav7_default_lift_follows_the_mass() -> None:
    """The default lift is the weight m g for any mass, so a unit turn command at level flight
    gives the same β̇ = g u_β / (V_a cos γ) whatever the mass; an explicit lift_n is kept."""
    x = np.array([0.0, 0.0, -20.0, 15.0, 0.3, 0.0, 0.0])
    u = np.array([0.0, 1.0, 1.0, 0.0])
    for mass in (2.0, 10.0, 25.0):
        dyn = Uav7Dynamics(mass_kg=mass)
        assert dyn.lift == pytest.approx(mass * dyn.gravity_mps2)
        assert uav7(dynamics=dyn).f(x, u)[4] == pytest.approx(dyn.gravity_mps2 / 15.0)
    assert Uav7Dynamics(lift_n=0.7).lift == 0.7
    with pytest.raises(InvalidInputError, match="lift_n"):
        uav7(dynamics=Uav7Dynamics(lift_n=-1.0))


def test_level_flight_rates_by_hand() -> None:
    """At β = γ = φ = 0: Ṅ = V_a + w_n, V̇_a = (u_Va − D)/m, β̇ = g u_β/V_a, γ̇ = g(u_γ − 1)/V_a."""
    x = [5.0, -3.0, -40.0, 20.0, 0.0, 0.0, 0.0]
    u = [10.9, 0.5, 1.5, -0.3]
    xdot = uav7().f(x, u, [1.0, -2.0, 0.5])
    g = GRAVITY_MPS2
    np.testing.assert_allclose(xdot, [21.0, -2.0, 0.5, (10.9 - 0.9) / 10.0, g * 0.5 / 20.0,
                                      g * 0.5 / 20.0, -0.3], atol=1e-12)


def test_climbing_turn_rates_by_hand() -> None:
    """Heading east (β = π/2) climbing at γ = π/6: Ė = V_a cos γ, Ḋ = −V_a sin γ, and gravity
    slows the airspeed by g sin γ; a bank φ scales the lift's share in γ̇ by cos φ."""
    va, gamma, phi = 20.0, math.pi / 6, math.pi / 3
    x = [0.0, 0.0, 0.0, va, math.pi / 2, gamma, phi]
    u = [0.9, 0.0, 2.0, 0.0]  # thrust = drag, load factor 2
    xdot = uav7().f(x, u)
    g = GRAVITY_MPS2
    want = [0.0, va * math.cos(gamma), -va * math.sin(gamma), -g * math.sin(gamma), 0.0,
            g / va * (math.cos(phi) * 2.0 - math.cos(gamma)), 0.0]
    np.testing.assert_allclose(xdot, want, atol=1e-12)


def test_straight_level_cruise_moves_at_airspeed_plus_wind() -> None:
    """With the nominal input the state stays level and the position moves by (V_a + w)·t."""
    model = uav7()
    x0 = np.array([0.0, 0.0, -50.0, 15.0, 0.0, 0.0, 0.0])
    x1 = model.step(x0, model.nominal_input, 4.0, [1.0, 2.0, 0.0], substeps=4)
    np.testing.assert_allclose(x1, [64.0, 8.0, -50.0, 15.0, 0.0, 0.0, 0.0], atol=1e-9)


def test_limits_and_nominal_input() -> None:
    """The boxes hold the given limits, cruise is (drag, 0, 1, 0) and rates are 10 or 20 per s."""
    model = uav7(altitude_band_m=(-260.0, 20.0))
    assert (model.nx, model.nu, model.n_wind) == (7, 4, 3)
    assert model.state_lower == (-math.inf, -math.inf, -260.0, 8.0, -math.inf, -0.5, -0.8)
    assert model.state_upper == (math.inf, math.inf, 20.0, 25.0, math.inf, 0.5, 0.8)
    assert model.input_lower == (-20.0, -1.0, 0.0, -1.0)
    assert model.input_upper == (40.0, 1.0, 2.0, 1.0)
    assert model.input_rate_max == (600.0, 20.0, 20.0, 20.0)
    assert model.nominal_input == (0.9, 0.0, 1.0, 0.0)
    assert model.angle_indices == (4,)


@pytest.mark.parametrize(("kwargs", "field"), [
    ({"dynamics": Uav7Dynamics(mass_kg=0.0)}, "mass_kg"),
    ({"dynamics": Uav7Dynamics(gravity_mps2=-9.81)}, "gravity_mps2"),
    ({"dynamics": Uav7Dynamics(drag_n=-0.1)}, "drag_n"),
    ({"airspeed_min_mps": 0.0}, "airspeed_min_mps"),
    ({"airspeed_max_mps": 7.0}, "airspeed_max_mps"),
    ({"flight_path_max_rad": 1.5}, "flight_path_max_rad"),
    ({"roll_max_rad": 0.0}, "roll_max_rad"),
    ({"thrust_max_n": -20.0}, "thrust_max_n"),
    ({"turn_input_max": 0.0}, "turn_input_max"),
    ({"roll_rate_max_rps": math.nan}, "roll_rate_max_rps"),
    ({"altitude_band_m": (10.0, -10.0)}, "altitude_band_m"),
    ({"thrust_min_n": 1.0}, "thrust_max_n"),  # thrust = drag (0.9 N) out of reach
])
def test_bad_limits_name_the_field(kwargs: dict[str, object], field: str) -> None:
    """Each bad limit raises InvalidInputError naming it."""
    with pytest.raises(InvalidInputError) as err:
        uav7(**kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_load_factor_below_level_flight_is_named() -> None:
    """A load factor limit below 1 (level flight) is refused naming load_factor_max; 1 is kept."""
    with pytest.raises(InvalidInputError) as err:
        uav7(load_factor_max=0.5)
    assert err.value.field == "load_factor_max"
    assert uav7(load_factor_max=1.0).input_upper[2] == 1.0
