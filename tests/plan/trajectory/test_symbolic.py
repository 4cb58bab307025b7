"""CasADi versions of the vehicle models: the namespace, the RK4 step and its Jacobians."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

from searchtrack.models.vehicles import fixed_wing, uav7, unicycle
from searchtrack.plan.trajectory.symbolic import (
    CASADI,
    dynamics_jacobians,
    step_function,
    step_jacobians,
    symbols,
)


def _dense(value: object) -> np.ndarray:
    return np.asarray(ca.DM(value)).astype(float)


def test_namespace_evaluates_like_numpy() -> None:
    """sin, cos and stack on CasADi numbers give NumPy's values, stacked as a column."""
    x = ca.DM(0.7)
    assert float(CASADI.sin(x)) == pytest.approx(math.sin(0.7))
    assert float(CASADI.cos(x)) == pytest.approx(math.cos(0.7))
    np.testing.assert_allclose(_dense(CASADI.stack([ca.DM(1), ca.DM(2), ca.DM(3)])),
                               [[1], [2], [3]])


@pytest.mark.parametrize("make", [unicycle, fixed_wing, uav7])
def test_symbols_are_sized_for_the_model(make: object) -> None:
    """x, u, wind and dt symbols have nx, nu, the number of position axes and 1 entries."""
    model = make()  # type: ignore[operator]
    x, u, p, dt = symbols(model)
    assert (x.numel(), u.numel(), p.numel(), dt.numel()) == (model.nx, model.nu, model.n_wind, 1)


@pytest.mark.parametrize("make", [unicycle, fixed_wing, uav7])
def test_step_function_matches_the_numpy_step(make: object) -> None:
    """The symbolic RK4 step equals the model's own NumPy step, wind included."""
    model = make()  # type: ignore[operator]
    rng = np.random.default_rng(4)
    x = 0.3 * rng.standard_normal(model.nx)
    if model.name == "uav7":
        x[3] = 15.0  # the airspeed divides the dynamics: keep it at cruise
    u = np.asarray(model.nominal_input) + 0.01 * rng.standard_normal(model.nu)
    wind = rng.standard_normal(model.n_wind)
    got = _dense(step_function(model)(x, u, wind, 0.2)).ravel()
    np.testing.assert_allclose(got, model.step(x, u, 0.2, wind), rtol=1e-12, atol=1e-12)


def test_unicycle_dynamics_jacobians_by_hand() -> None:
    """For ẋ = (v cos θ, v sin θ, ω): ∂f/∂x has −v sin θ, v cos θ in the heading column and
    ∂f/∂u = [[cos θ, 0], [sin θ, 0], [0, 1]]."""
    v, th = 12.0, 0.4
    a, b = dynamics_jacobians(unicycle())([3.0, -1.0, th], [v, 0.2], [0.5, 0.5])
    np.testing.assert_allclose(_dense(a), [[0, 0, -v * math.sin(th)], [0, 0, v * math.cos(th)],
                                           [0, 0, 0]], atol=1e-15)
    np.testing.assert_allclose(_dense(b), [[math.cos(th), 0], [math.sin(th), 0], [0, 1]],
                               atol=1e-15)


@pytest.mark.parametrize("make", [unicycle, fixed_wing])
def test_step_jacobians_match_finite_differences(make: object) -> None:
    """∂x⁺/∂x and ∂x⁺/∂u of the RK4 step agree with central differences of the NumPy step."""
    model = make()  # type: ignore[operator]
    x = np.array([1.0, 2.0, 0.3]) if model.nx == 3 else np.array([1.0, 2.0, 20.0, 0.3, 0.1])
    u = np.asarray(model.nominal_input) + 0.1
    wind = np.full(model.n_wind, 0.5)
    nxt, a, b = step_jacobians(model)(x, u, wind, 0.1)
    np.testing.assert_allclose(_dense(nxt).ravel(), model.step(x, u, 0.1, wind), atol=1e-12)
    eps = 1e-6
    fd_a = np.column_stack([(model.step(x + eps * e, u, 0.1, wind)
                             - model.step(x - eps * e, u, 0.1, wind)) / (2 * eps)
                            for e in np.eye(model.nx)])
    fd_b = np.column_stack([(model.step(x, u + eps * e, 0.1, wind)
                             - model.step(x, u - eps * e, 0.1, wind)) / (2 * eps)
                            for e in np.eye(model.nu)])
    np.testing.assert_allclose(_dense(a), fd_a, atol=1e-7)
    np.testing.assert_allclose(_dense(b), fd_b, atol=1e-7)


def test_functions_are_cached_per_model() -> None:
    """Equal models share one built function; a different model gets its own."""
    assert step_function(unicycle()) is step_function(unicycle())
    assert step_jacobians(unicycle()) is step_jacobians(unicycle())
    assert step_function(unicycle(speed_max_mps=20.0)) is not step_function(unicycle())
