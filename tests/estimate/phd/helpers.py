"""A 1 km square, a position sensor over it and Gaussian particle clouds for the PHD tests."""

from __future__ import annotations

import numpy as np

from searchtrack.estimate.phd import PHDState
from searchtrack.models.position_sensor import PositionSensor

AREA = np.array([[0.0, 1000.0], [0.0, 1000.0]])
POSE = np.zeros(3)


def sensor(pd: float = 0.9, clutter: float = 10.0) -> PositionSensor:
    """A position sensor over AREA with σ = 10 m, detection probability ``pd`` and ``clutter``
    false alarms per scan."""
    return PositionSensor(pd, 10.0, clutter, AREA)


def cloud(centre: tuple[float, float], n: int, mass: float, spread: float = 5.0,
          seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``n`` constant-velocity states (at rest) around ``centre`` with Gaussian spread (m),
    sharing ``mass`` equally."""
    rng = np.random.default_rng(seed)
    x = np.zeros((n, 4))
    x[:, :2] = np.asarray(centre) + spread * rng.standard_normal((n, 2))
    return x, np.full(n, mass / n)


def phd_state(*clouds: tuple[np.ndarray, np.ndarray]) -> PHDState:
    """The PHD holding all of ``clouds``."""
    return PHDState.from_particles(np.vstack([c[0] for c in clouds]),
                                   np.concatenate([c[1] for c in clouds]))
