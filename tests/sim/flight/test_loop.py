"""Closed-loop flights: constraint satisfaction, fallbacks counted, determinism, plots, errors."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.vehicles import VehicleModel, uav7, unicycle
from searchtrack.plan.trajectory import Obstacles, waypoint_path
from searchtrack.sim.flight.loop import FlightConfig, FlightLog, fly, plot_flight

REF = waypoint_path([[0, 0], [80, 0], [80, 60]], 10.0)
OBS = Obstacles(centers_m=np.array([[25, 1], [50, -2], [80, 30]], dtype=float),
                radii_m=np.array([4.0, 3.0, 4.0]))


def test_nmpc_flight_keeps_clear_and_within_bounds() -> None:
    """NMPC flies the course with no obstacle penetration and inputs inside box and rate limits."""
    model = unicycle()
    log = fly(model, [0, -3, 0], REF, OBS, FlightConfig(backend="nmpc", time_limit_s=1.0),
              rng=np.random.default_rng(0))
    assert log.collisions == 0 and log.min_clearance_m > 0.0
    assert np.all(log.inputs >= np.asarray(model.input_lower) - 1e-6)
    assert np.all(log.inputs <= np.asarray(model.input_upper) + 1e-6)
    rates = np.abs(np.diff(log.inputs, axis=0)) / 0.1
    assert np.all(rates <= np.asarray(model.input_rate_max) + 1e-3)
    assert log.count("nmpc") == len(log.controllers)
    assert log.rms_error_m < 5.0


def test_auto_flight_with_wind_and_noise_counts_controllers() -> None:
    """Under wind and noise auto flies without collision; every step names its controller."""
    log = fly(unicycle(), [0, -3, 0], REF, OBS,
              FlightConfig(backend="auto", time_limit_s=0.5, wind_mps=(1.0, -0.5),
                           process_noise=(0.05, 0.05, 0.01)), rng=np.random.default_rng(1))
    assert log.collisions == 0
    assert set(log.controllers) <= {"nmpc", "ltv_mpc", "closed_form"}
    assert log.states.shape == (len(log.controllers) + 1, 3)


def test_flights_are_deterministic_for_a_seed(tmp_path: Path) -> None:
    """Two closed-form flights with the same seed and noise agree; the plot is a PNG file."""
    cfg = FlightConfig(backend="closed_form", process_noise=(0.1, 0.1, 0.01), duration_s=5.0)
    a = fly(unicycle(), [0, -3, 0], REF, OBS, cfg, rng=np.random.default_rng(7))
    b = fly(unicycle(), [0, -3, 0], REF, OBS, cfg, rng=np.random.default_rng(7))
    np.testing.assert_array_equal(a.states, b.states)
    out = plot_flight(a, tmp_path / "flight.png", OBS)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_bad_flight_inputs_are_rejected() -> None:
    """A start inside an obstacle, a wrong wind size or negative noise raise InvalidInputError."""
    with pytest.raises(InvalidInputError, match="inside obstacle"):
        fly(unicycle(), [25, 1, 0], REF, OBS, rng=np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="wind_mps"):
        fly(unicycle(), [0, 0, 0], REF, OBS, FlightConfig(wind_mps=(1.0, 2.0, 3.0)),
            rng=np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="process_noise"):
        fly(unicycle(), [0, 0, 0], REF, OBS, FlightConfig(process_noise=(-1.0, 0.0, 0.0)),
            rng=np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="horizon"):
        FlightConfig(horizon=0)


def assert_within_limits(log: FlightLog, model: VehicleModel, dt_s: float = 0.1) -> None:
    """Inputs inside the box, input rates inside their limits, no obstacle entered."""
    lo, hi = np.asarray(model.input_lower), np.asarray(model.input_upper)
    assert np.all(log.inputs >= lo - 1e-6) and np.all(log.inputs <= hi + 1e-6)
    applied = np.vstack([model.nominal_input, log.inputs])
    rates = np.abs(np.diff(applied, axis=0)) / dt_s
    assert np.all(rates <= np.asarray(model.input_rate_max) * (1 + 1e-6) + 1e-6)
    assert log.collisions == 0 and np.all(log.clearance_m >= 0.0)


@pytest.mark.parametrize("backend", ["ltv_mpc", "closed_form"])
def test_fallback_controllers_respect_limits_in_closed_loop(backend: str) -> None:
    """The OSQP QP and the closed-form law keep box and rate limits and stay out of obstacles
    along a whole flight with wind."""
    model = unicycle()
    log = fly(model, [0, -3, 0], REF, OBS,
              FlightConfig(backend=backend, time_limit_s=0.5, wind_mps=(0.5, -0.5)),
              rng=np.random.default_rng(0))
    assert_within_limits(log, model)
    assert log.count(backend) == len(log.controllers)
    assert log.rms_error_m < 20.0  # the pursuit law swerves wide around the cylinders


def test_uav7_nmpc_in_3d_respects_input_and_state_limits() -> None:
    """The 7-state UAV under NMPC climbs a 3-D course past a sphere and a cylinder with wind:
    inputs, input rates and airspeed / flight-path / roll boxes hold, clearance stays ≥ 0."""
    model = uav7()
    ref = waypoint_path([[0, 0, -20], [100, 0, -30], [100, 100, -30]], 15.0)
    obs = Obstacles(centers_m=np.array([[40, 2, -24], [100, 45, 0]], dtype=float),
                    radii_m=np.array([4.0, 5.0]),
                    cylinder=np.array([False, True]))
    start = [0.0, -5.0, -20.0, 15.0, 0.0, 0.0, 0.0]
    log = fly(model, start, ref, obs,
              FlightConfig(backend="nmpc", time_limit_s=1.0, wind_mps=(2.0, 0.0, 0.0),
                           duration_s=ref.duration_s), rng=np.random.default_rng(0))
    assert_within_limits(log, model)
    lo, hi = np.asarray(model.state_lower), np.asarray(model.state_upper)
    assert np.all(log.states >= lo - 1e-4) and np.all(log.states <= hi + 1e-4)
    assert log.state_violations == 0
    outside = dataclasses.replace(log, states=log.states + np.r_[0, 0, 0, 50.0, 0, 0, 0])
    assert outside.state_violations == len(log.states)  # airspeed above its bound everywhere
    assert log.min_clearance_m < 5.0  # the obstacles were in play
    assert log.rms_error_m < 5.0
