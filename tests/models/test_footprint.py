"""The Gaussian field of view and the batched detection matrix."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.footprint import (
    BatchDetectionSensor,
    GaussianFieldOfView,
    detection_matrix,
)
from searchtrack.models.particle_models import DetectionSensor

FOV = GaussianFieldOfView(0.9, 10.0, 30.0)


def test_gaussian_values_peak_and_scales() -> None:
    """p_d is the peak under the UAV and falls by e^{-1/2} one scale away on each axis;
    2-D positions sit on the ground."""
    pose = np.array([5.0, -2.0, 30.0, 0.4, 0.0])
    pts = np.array([[5.0, -2.0, 30.0], [15.0, -2.0, 30.0], [5.0, -2.0, 0.0]])
    np.testing.assert_allclose(FOV.detection_probability(pose, pts),
                               [0.9, 0.9 * np.exp(-0.5), 0.9 * np.exp(-0.5)], rtol=1e-12)
    np.testing.assert_allclose(FOV.detection_probability(pose, pts[2:, :2]),
                               [0.9 * np.exp(-0.5)], rtol=1e-12)
    assert isinstance(FOV, DetectionSensor) and isinstance(FOV, BatchDetectionSensor)


def test_casadi_expression_matches_numpy() -> None:
    """The symbolic footprint the NLP differentiates equals the NumPy one."""
    import casadi as ca

    rng = np.random.default_rng(0)
    pts = rng.uniform(-20.0, 20.0, size=(7, 2))
    q = ca.SX.sym("q", 3)
    f = ca.Function("pd", [q], [FOV.casadi_detection(q, pts)])
    pose = np.array([1.0, 2.0, 12.0])
    np.testing.assert_allclose(np.asarray(f(pose)).ravel(), FOV.detection_probability(pose, pts),
                               rtol=1e-12)


@dataclass(frozen=True)
class _OnePose:
    """A sensor with only the one-pose method, returning values outside [0, 1]."""

    meas_dim: int = 2

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        return np.full(positions.shape[0], pose[0])

    def likelihood(self, pose: FloatArray, z: FloatArray, positions: FloatArray) -> FloatArray:
        return np.zeros((z.shape[0], positions.shape[0]))

    def clutter_intensity(self, pose: FloatArray, z: FloatArray) -> FloatArray:
        return np.zeros(z.shape[0])

    def to_position(self, pose: FloatArray, z: FloatArray) -> FloatArray:
        return z


def test_detection_matrix_batches_and_clips() -> None:
    """The matrix equals pose-by-pose evaluation and is clipped to [0, 1]."""
    rng = np.random.default_rng(1)
    poses = np.column_stack([rng.uniform(-30, 30, (4, 2)), rng.uniform(5, 40, 4)])
    pts = rng.uniform(-30, 30, (9, 3))
    np.testing.assert_allclose(detection_matrix(FOV, poses, pts),
                               [FOV.detection_probability(q, pts) for q in poses], rtol=1e-12)
    clipped = detection_matrix(_OnePose(), np.array([[-0.5, 0, 0], [0.3, 0, 0], [2.0, 0, 0]]),
                               pts)
    np.testing.assert_allclose(clipped[:, 0], [0.0, 0.3, 1.0])


def test_bad_footprint_and_detection_only() -> None:
    """Bad parameters name the field; the model has no measurements and no clutter."""
    with pytest.raises(InvalidInputError, match="peak_pd"):
        GaussianFieldOfView(peak_pd=1.5)
    with pytest.raises(InvalidInputError, match="scale_z_m"):
        GaussianFieldOfView(scale_z_m=0.0)
    with pytest.raises(NotImplementedError):
        FOV.likelihood(np.zeros(3), np.zeros((1, 3)), np.zeros((1, 3)))
    assert FOV.clutter_intensity(np.zeros(3), np.zeros((2, 3))).tolist() == [0.0, 0.0]
