"""Vehicle models: CasADi Jacobians vs finite differences, RK4 vs a fine integration, bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.dubins import DubinsLimits, unicycle_from_limits
from searchtrack.models.vehicles import VehicleModel, fixed_wing, uav7, unicycle
from searchtrack.models.vehicles.uav7 import Uav7Dynamics
from searchtrack.models.vehicles.unicycle import UnicycleDynamics
from searchtrack.plan.trajectory.symbolic import dynamics_jacobians, step_function, step_jacobians

MODELS = {"unicycle": unicycle(), "fixed_wing": fixed_wing(), "uav7": uav7()}


def _sample(model: VehicleModel, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    lo = np.where(np.isfinite(model.state_lower), model.state_lower, -50.0)
    hi = np.where(np.isfinite(model.state_upper), model.state_upper, 50.0)
    x = rng.uniform(lo, hi)
    for i in model.angle_indices:
        x[i] = rng.uniform(-math.pi, math.pi)
    u = rng.uniform(model.input_lower, model.input_upper)
    return x, u


def _fd(fun: object, x: np.ndarray, eps: float = 1e-6) -> np.ndarray:
    f0 = fun(x)  # type: ignore[operator]
    cols = []
    for i in range(x.size):
        d = np.zeros_like(x)
        d[i] = eps
        cols.append((fun(x + d) - fun(x - d)) / (2 * eps))  # type: ignore[operator]
    return np.column_stack(cols).reshape(np.size(f0), x.size)


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


def test_unicycle_wind_drifts_and_turns_at_the_commanded_rate() -> None:
    """Unicycle: wind adds to the velocity and the heading changes by ω·t."""
    model = unicycle()
    x = model.step([0.0, 0.0, 0.0], [10.0, 0.5], 2.0, [1.0, -2.0], substeps=200)
    assert x[2] == pytest.approx(1.0)
    radius = 10.0 / 0.5
    assert x[0] == pytest.approx(radius * math.sin(1.0) + 2.0, abs=1e-8)
    assert x[1] == pytest.approx(radius * (1 - math.cos(1.0)) - 4.0, abs=1e-8)


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


def test_from_limits_copies_the_potential_field_limits() -> None:
    """unicycle_from_limits takes the speed and turn-rate limits of DubinsLimits."""
    limits = DubinsLimits(speed_max_mps=30.0, speed_min_mps=20.0, turn_rate_max_rps=0.7)
    model = unicycle_from_limits(limits)
    assert model.input_lower == (20.0, -0.7)
    assert model.input_upper == (30.0, 0.7)


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


def test_vehicle_models_do_not_import_casadi() -> None:
    """Importing searchtrack.models.vehicles loads neither CasADi nor the plan layer."""
    import subprocess
    import sys

    code = ("import sys, searchtrack.models.vehicles\n"
            "bad = [m for m in sys.modules if m.startswith(('casadi', 'searchtrack.plan'))]\n"
            "assert not bad, bad")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr[-2000:]
