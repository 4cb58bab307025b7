"""Shared small tracking problems: a unicycle course past obstacles."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.models.vehicles import unicycle
from searchtrack.plan.trajectory import Obstacles, TrackingProblem, waypoint_path


@pytest.fixture
def course() -> TrackingProblem:
    """A unicycle heading east along y = 0 with five cylinders, two on the path."""
    return TrackingProblem(
        unicycle(), np.array([0.0, -3.0, 0.0]),
        waypoint_path([[0, 0], [100, 0], [100, 100]], 10.0),
        obstacles=Obstacles(centers_m=[[20, 1], [45, -2], [100, 40], [70, 30], [40, 30]],
                            radii_m=[4, 3, 5, 4, 3]),
        horizon=20, dt_s=0.1, safety_margin_m=1.0)
