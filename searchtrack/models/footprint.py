"""Detection footprints: ``p_d`` of many sensor poses at once, and a smooth Gaussian field of view.

:func:`detection_matrix` is what the planners call: the ``(K, N)`` detection probabilities of
``N`` positions from ``K`` poses, in one call when the sensor is a :class:`BatchDetectionSensor`.
:class:`GaussianFieldOfView` is a detection-only planning model (paper 004 eq. 1, squared)::

    p_d(x | q) = G · exp(−½ ‖((x − q_x)/F_x, (y − q_y)/F_y, (z − q_z)/F_z)‖²)

with ground targets (2-D positions) at ``z = 0``. It implements
:class:`~searchtrack.models.particle_models.DetectionSensor` (detection only: no measurements, no
clutter) plus a CasADi expression, so a nonlinear program can differentiate it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np

from searchtrack.core.checks import positive, real
from searchtrack.core.types import FloatArray
from searchtrack.models.particle_models import DetectionSensor


@runtime_checkable
class BatchDetectionSensor(Protocol):
    """A sensor that also evaluates many poses at once (optional; speeds up the planners)."""

    def detection_probabilities(self, poses: FloatArray, positions: FloatArray) -> FloatArray:
        """``(K, N)`` values ``p_d(x_j | q_k)`` for ``(K, pose_dim)`` poses."""
        ...


def detection_matrix(sensor: DetectionSensor, poses: FloatArray,
                     positions: FloatArray) -> FloatArray:
    """``(K, N)`` detection probabilities of ``positions`` from each of ``(K, pose_dim)`` poses,
    clipped to ``[0, 1]``."""
    if isinstance(sensor, BatchDetectionSensor):
        out = np.asarray(sensor.detection_probabilities(poses, positions), dtype=np.float64)
    else:
        out = np.empty((poses.shape[0], positions.shape[0]))
        for k, pose in enumerate(poses):
            out[k] = sensor.detection_probability(pose, positions)
    if out.size and (out.min() < 0.0 or out.max() > 1.0):
        out = np.clip(out, 0.0, 1.0)
    return out


def _as_3d(positions: FloatArray) -> FloatArray:
    p = np.asarray(positions, dtype=np.float64)
    return p if p.shape[1] == 3 else np.concatenate([p, np.zeros((p.shape[0], 1))], axis=1)


@dataclass(frozen=True)
class GaussianFieldOfView:
    """Gaussian detection footprint with peak ``peak_pd`` and scales ``F = (fxy, fxy, fz)`` (m)."""

    peak_pd: float = 0.9
    scale_xy_m: float = 10.0
    scale_z_m: float = 30.0

    def __post_init__(self) -> None:
        real("peak_pd", self.peak_pd, low=0.0, high=1.0, low_open=True)
        positive("scale_xy_m", self.scale_xy_m)
        positive("scale_z_m", self.scale_z_m)

    @property
    def meas_dim(self) -> int:
        """Unused by the planners (detection-only model)."""
        return 3

    @property
    def _inv_scale2(self) -> FloatArray:
        return 1.0 / np.array([self.scale_xy_m, self.scale_xy_m, self.scale_z_m]) ** 2

    def detection_probabilities(self, poses: FloatArray, positions: FloatArray) -> FloatArray:
        """``(K, N)`` detection probabilities."""
        q = np.asarray(poses, dtype=np.float64)[:, :3]
        x = _as_3d(positions)
        s = self._inv_scale2
        d2 = (np.square(q[:, None, 0] - x[None, :, 0]) * s[0]
              + np.square(q[:, None, 1] - x[None, :, 1]) * s[1]
              + np.square(q[:, None, 2] - x[None, :, 2]) * s[2])
        out: FloatArray = self.peak_pd * np.exp(-0.5 * d2)
        return out

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N,)`` detection probabilities from one pose."""
        out: FloatArray = self.detection_probabilities(np.asarray(pose)[None, :], positions)[0]
        return out

    def casadi_detection(self, q: Any, positions: FloatArray) -> Any:
        """CasADi ``(N, 1)`` expression of ``p_d`` for a symbolic position ``q`` ``(3, 1)``."""
        import casadi as ca

        x = _as_3d(positions)
        s = self._inv_scale2
        d2 = ((ca.DM(x[:, 0]) - q[0]) ** 2 * s[0] + (ca.DM(x[:, 1]) - q[1]) ** 2 * s[1]
              + (ca.DM(x[:, 2]) - q[2]) ** 2 * s[2])
        return self.peak_pd * ca.exp(-0.5 * d2)

    def likelihood(self, pose: FloatArray, measurements: FloatArray,
                   positions: FloatArray) -> FloatArray:
        """Detection-only model: raises."""
        raise NotImplementedError("GaussianFieldOfView is a planning model without measurements")

    def clutter_intensity(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """No clutter."""
        return np.zeros(np.asarray(measurements).shape[0])

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """Detection-only model: raises."""
        raise NotImplementedError("GaussianFieldOfView is a planning model without measurements")
