"""Tiny sensors and random instances shared by the assignment tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.estimate.particle_belief import WeightedParticles
from searchtrack.plan.assign import (
    AssignmentProblem,
    ExpectedDetections,
    MutualInformation,
    Objective,
)

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class DiscSensor:
    """p_d = peak inside a ground disc of radius_m under the UAV, 0 outside (optionally soft)."""

    radius_m: float = 10.0
    peak: float = 0.8
    gaussian: bool = False

    @property
    def meas_dim(self) -> int:
        return 2

    def detection_probabilities(self, poses: FloatArray, positions: FloatArray) -> FloatArray:
        d2 = np.sum((poses[:, None, :2] - positions[None, :, :2]) ** 2, axis=2)
        if self.gaussian:
            out: FloatArray = self.peak * np.exp(-0.5 * d2 / self.radius_m**2)
            return out
        return np.where(d2 <= self.radius_m**2, self.peak, 0.0)

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        return self.detection_probabilities(np.asarray(pose)[None, :], positions)[0]

    def likelihood(self, pose: FloatArray, measurements: FloatArray,
                   positions: FloatArray) -> FloatArray:
        return np.zeros((measurements.shape[0], positions.shape[0]))

    def clutter_intensity(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        return np.zeros(measurements.shape[0])

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        return np.asarray(measurements, dtype=np.float64)


def objective_named(name: str) -> Objective:
    """``"end"`` → :class:`ExpectedDetections`, ``"mi"`` → :class:`MutualInformation`."""
    return {"end": ExpectedDetections(), "mi": MutualInformation()}[name]


def random_problem(rng: np.random.Generator, robots: int = 3, actions: int = 4, steps: int = 1,
                   particles: int = 60, objective: str = "end", gaussian: bool = False,
                   separation: float = 0.0) -> AssignmentProblem:
    """Random UAV poses over a 50 m square and random particles with weights summing to ~3."""
    acts = []
    for _ in range(robots):
        xy = rng.uniform(0.0, 50.0, size=(actions, steps, 2))
        z = np.full((actions, steps, 1), 20.0)
        acts.append(np.concatenate([xy, z], axis=2))
    pos = rng.uniform(0.0, 50.0, size=(particles, 2))
    w = rng.uniform(0.0, 1.0, size=particles)
    w *= 3.0 / w.sum()
    return AssignmentProblem(tuple(acts), WeightedParticles(pos, w), DiscSensor(gaussian=gaussian),
                             objective=objective_named(objective), min_separation_m=separation)
