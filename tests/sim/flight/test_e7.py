"""Paper 004's experiment E7: the exploration planner's waypoints flown by the 7-state UAV past
three spheres, and the setup's input checks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.sim.flight.e7 import E7Setup, fly_e7
from searchtrack.sim.flight.loop import FlightConfig, plot_flight


def test_e7_closed_form_flight_keeps_clear_of_the_spheres() -> None:
    """E7 with the backstepping law (d_l = 6 m) and 3 m/s wind: no collision, the spheres near."""
    run = fly_e7(0, setup=E7Setup(steps=40))
    flight = run.flight
    assert run.obstacles.k == 3 and not np.any(run.obstacles.is_cylinder)
    assert flight.collisions == 0 and 0.0 < flight.min_clearance_m < 6.0
    assert flight.count("closed_form") == len(flight.controllers)
    assert run.targets_found >= 1 and run.waypoints_m.shape == (41, 3)


def test_e7_auto_flight_tracks_closely(tmp_path: Path) -> None:
    """E7 under ``auto``: no collision, clearance kept, tracking within a few metres; the plot
    of a 3-D flight (top view and altitude) is a PNG."""
    run = fly_e7(1, setup=E7Setup(steps=25), config=FlightConfig(backend="auto",
                                                                 time_limit_s=0.2))
    assert run.flight.collisions == 0 and run.flight.min_clearance_m > 0.0
    assert run.flight.rms_error_m < 5.0
    out = plot_flight(run.flight, tmp_path / "e7.png", run.obstacles)
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_bad_setups_name_the_field() -> None:
    """A setup without steps, a NaN slope and a negative seed raise InvalidInputError."""
    with pytest.raises(InvalidInputError, match="steps"):
        E7Setup(steps=0)
    with pytest.raises(InvalidInputError, match="max_slope"):
        E7Setup(max_slope=float("nan"))
    with pytest.raises(InvalidInputError, match="seed"):
        fly_e7(-1)
