"""One scan of the SMC-PHD filter: predict, update, extract, resample."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from searchtrack.estimate.phd.config import PHDConfig
from searchtrack.estimate.phd.extract import Estimates, extract
from searchtrack.estimate.phd.predict import predict
from searchtrack.estimate.phd.resample import resample
from searchtrack.estimate.phd.state import PHDState
from searchtrack.estimate.phd.update import SensorScan, update
from searchtrack.models.particle_models import MotionModel


def step(state: PHDState, scans: Sequence[SensorScan], motion: MotionModel, config: PHDConfig,
         dt_s: float, rng: np.random.Generator) -> tuple[PHDState, Estimates]:
    """The posterior after one scan (``dt_s`` after ``state``) and its point estimates.

    Extraction runs on the updated weights, before resampling.
    """
    return assimilate(predict(state, motion, config, dt_s, rng), scans, config, rng)


def assimilate(predicted: PHDState, scans: Sequence[SensorScan], config: PHDConfig,
               rng: np.random.Generator) -> tuple[PHDState, Estimates]:
    """The update of :func:`step` on an already predicted PHD: the posterior after ``scans``
    (resampled) and its point estimates (extracted before resampling)."""
    updated = update(predicted, scans, config)
    estimates = extract(updated, config)
    return resample(updated, config, rng), estimates
