"""Malformed input across the SMC-PHD filter's constructors and steps names the field."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import BirthGrid, PHDConfig, PHDState, SensorScan, predict
from searchtrack.models.motion import ConstantVelocity

from .helpers import AREA, POSE
from .helpers import sensor as _sensor


def test_bad_scans_and_states() -> None:
    """Malformed measurements, particles and birth grids are rejected with the field named."""
    with pytest.raises(InvalidInputError, match="measurements"):
        SensorScan(_sensor(), POSE, np.zeros((2, 3)))
    with pytest.raises(InvalidInputError, match="measurements"):
        SensorScan(_sensor(), POSE, np.array([[np.nan, 1.0]]))
    with pytest.raises(InvalidInputError, match="weights"):
        PHDState.from_particles(np.zeros((2, 4)), np.array([1.0, -1.0]))
    with pytest.raises(InvalidInputError, match="cell_weights"):
        BirthGrid(AREA, np.zeros((2, 2)), 1.0, 10)
    with pytest.raises(InvalidInputError, match="birth_grid"):
        grid = BirthGrid(np.array([[0.0, 1.0]]), np.ones(3), 1.0, 10)
        predict(PHDState.empty(4), ConstantVelocity(0.5), PHDConfig(birth_grid=grid), 1.0,
                np.random.default_rng(0))
