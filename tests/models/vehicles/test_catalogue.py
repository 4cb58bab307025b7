"""Every vehicle model: CasADi Jacobians vs finite differences, RK4 vs a fine integration,
batched dynamics, and bad input named by field."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle
from searchtrack.models.vehicles.unicycle import UnicycleDynamics
from searchtrack.plan.trajectory.symbolic import dynamics_jacobians, step_function, step_jacobians
from tests.models.vehicles.catalogue import MODELS
from tests.models.vehicles.catalogue import central_differences as _fd
from tests.models.vehicles.catalogue import sample as _sample


@pytest.mark.parametrize("name", list(MODELS))
def test_casadi_jacobians_match_finite_differences(name: str) -> None:
    """∂f/∂x and ∂f/∂u from CasADi equal central differences of the NumPy dynamics."""
    model = MODELS[name]
    rng = np.random.default_rng(1)
    wind = rng.normal(0, 2, model.n_wind)
    for _ in range(3):
        x, u = _sample(model, rng)
        a, b = (np.asarray(j) for j in dynamics_jacobians(model)(x, u, wind))
        fd_x = _fd(lambda z, u=u: model.f(z, u, wind), x)
        fd_u = _fd(lambda z, x=x: model.f(x, z, wind), u)
        np.testing.assert_allclose(a, fd_x, atol=1e-6, rtol=1e-6)
        np.testing.assert_allclose(b, fd_u, atol=1e-6, rtol=1e-6)


@pytest.mark.parametrize("name", list(MODELS))
def test_step_jacobians_match_finite_differences(name: str) -> None:
    """The RK4 step's CasADi Jacobians equal central differences of the NumPy RK4 step."""
    model = MODELS[name]
    rng = np.random.default_rng(2)
    x, u = _sample(model, rng)
    wind = np.zeros(model.n_wind)
    nxt, a, b = (np.asarray(j) for j in step_jacobians(model)(x, u, wind, 0.1))
    np.testing.assert_allclose(nxt.ravel(), model.step(x, u, 0.1), atol=1e-10)
    np.testing.assert_allclose(a, _fd(lambda z: model.step(z, u, 0.1), x), atol=1e-6, rtol=1e-6)
    np.testing.assert_allclose(b, _fd(lambda z: model.step(x, z, 0.1), u), atol=1e-6, rtol=1e-6)


@pytest.mark.parametrize("name", list(MODELS))
def test_rk4_matches_fine_integration(name: str) -> None:
    """One 0.1 s RK4 step (NumPy and CasADi) agrees with solve_ivp at tight tolerances."""
    model = MODELS[name]
    rng = np.random.default_rng(3)
    x, u = _sample(model, rng)
    wind = rng.normal(0, 1, model.n_wind)
    fine = solve_ivp(lambda _t, z: model.f(z, u, wind), (0.0, 0.1), x, rtol=1e-11, atol=1e-11)
    np.testing.assert_allclose(model.step(x, u, 0.1, wind), fine.y[:, -1], atol=1e-6)
    sym = np.asarray(step_function(model)(x, u, wind, 0.1)).ravel()
    np.testing.assert_allclose(sym, model.step(x, u, 0.1, wind), atol=1e-12)


@pytest.mark.parametrize("name", list(MODELS))
def test_batched_dynamics_match_columns(name: str) -> None:
    """f on a (nx, batch) array equals f column by column."""
    model = MODELS[name]
    rng = np.random.default_rng(4)
    pairs = [_sample(model, rng) for _ in range(4)]
    xs, us = np.column_stack([p[0] for p in pairs]), np.column_stack([p[1] for p in pairs])
    batched = model.f(xs, us)
    for i, (x, u) in enumerate(pairs):
        np.testing.assert_allclose(batched[:, i], model.f(x, u))


def test_bad_inputs_name_the_field() -> None:
    """Inverted ranges, NaN states, states outside the box and ragged bounds are rejected."""
    with pytest.raises(InvalidInputError, match="speed_min_mps"):
        unicycle(speed_min_mps=20.0, speed_max_mps=10.0)
    with pytest.raises(InvalidInputError, match="altitude_max_m"):
        fixed_wing(altitude_min_m=10.0, altitude_max_m=5.0)
    with pytest.raises(InvalidInputError, match="state"):
        uav7().check_state("state", [0, 0, 0, math.nan, 0, 0, 0])
    with pytest.raises(InvalidInputError, match="airspeed_mps"):
        uav7().check_state("state", [0, 0, 0, 2.0, 0, 0, 0])
    with pytest.raises(InvalidInputError, match="input_lower"):
        VehicleModel("bad", ("x",), ("u",), UnicycleDynamics(), (0.0,), (1.0,), (0.0, 1.0),
                     (1.0,), (1.0,), (0.5,), (0, 0))
    with pytest.raises(InvalidInputError, match="nominal_input"):
        VehicleModel("bad", ("x", "y", "t"), ("v", "w"), UnicycleDynamics(), (0.0,) * 3,
                     (1.0,) * 3, (0.0, 0.0), (1.0, 1.0), (1.0, 1.0), (2.0, 0.0), (0, 1))
