"""The SMC-PHD filter (papers 003, 004) as a :class:`~searchtrack.estimate.stepping.SteppedFilter`.

:func:`~searchtrack.estimate.phd.filter.step` is one scan: predict, update, extract, resample.
:class:`PHDFilter` splits it at the scan, so a closed loop predicts and updates it like any
other filter: :meth:`PHDFilter.predict` is :func:`~searchtrack.estimate.phd.predict.predict`;
:meth:`PHDFilter.update` is the sequential multi-sensor update of one scan of every sensor
(one measurement array per sensor pose), then the extraction on the updated weights and the
resampling, and it returns the point estimates. A predict and an update in a row with one
generator draw exactly what one ``step`` draws. The filter owns its generator.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.phd.config import PHDConfig
from searchtrack.estimate.phd.extract import Estimates
from searchtrack.estimate.phd.filter import assimilate
from searchtrack.estimate.phd.predict import predict
from searchtrack.estimate.phd.state import PHDState
from searchtrack.estimate.phd.update import SensorScan
from searchtrack.models.particle_models import DetectionSensor, MotionModel


class PHDFilter:
    """A particle PHD stepped by predict and update, with its models and generator.

    Parameters
    ----------
    state
        The initial PHD (e.g. :meth:`PHDState.empty`).
    motion
        Single-target motion model.
    sensor
        The sensor model of every pose.
    config
        Survival, birth, extraction and resampling settings.
    rng
        The filter's generator (births, motion noise, resampling).
    """

    def __init__(self, state: PHDState, motion: MotionModel, sensor: DetectionSensor,
                 config: PHDConfig, rng: np.random.Generator) -> None:
        if not isinstance(state, PHDState):
            raise InvalidInputError("state", state, "must be a PHDState")
        self.motion, self.sensor, self.config = motion, sensor, config
        self._rng = checks.generator("rng", rng)
        self._state = state
        self._estimates = Estimates(np.empty((0, state.state_dim)), np.empty(0),
                                    state.position_dim)

    @property
    def state(self) -> PHDState:
        """The current PHD (after the last prediction or update)."""
        return self._state

    @property
    def estimates(self) -> Estimates:
        """The point estimates of the last update (none before the first)."""
        return self._estimates

    def predict(self, dt_s: float) -> None:
        """Survival, motion and births over ``dt_s`` seconds (paper 003, eq. 4)."""
        self._state = predict(self._state, self.motion, self.config, dt_s, self._rng)

    def update(self, scan: Sequence[ArrayLike], pose: ArrayLike) -> Estimates:
        """Update with ``scan[i]``, the ``(k_i, meas_dim)`` measurements taken from pose
        ``pose[i]`` (paper 003, eq. 5, sensor after sensor), extract and resample.

        Raises
        ------
        InvalidInputError
            ``pose`` is not one pose per measurement array.
        """
        poses = np.atleast_2d(np.asarray(pose, dtype=np.float64))
        if poses.ndim != 2 or poses.shape[0] != len(scan):
            raise InvalidInputError("pose", poses.shape,
                                    f"must hold one pose per measurement array ({len(scan)})")
        scans = [SensorScan(self.sensor, q, np.asarray(z, dtype=np.float64))
                 for q, z in zip(poses, scan, strict=True)]
        self._state, self._estimates = assimilate(self._state, scans, self.config, self._rng)
        return self._estimates

    def estimates_xy(self) -> FloatArray:
        """``(k, 2)`` ground positions of the last update's estimates."""
        return np.array(self._estimates.positions[:, :2], dtype=np.float64)
