"""A position sensor over a rectangle: constant ``p_d``, Gaussian noise, uniform clutter.

The standard multi-target tracking benchmark sensor: a target inside ``area`` is detected with
probability ``pd`` and measured at its position plus ``N(0, σ² I)`` noise; a Poisson number (mean
``clutter_rate``) of false alarms falls uniformly over the area, so the clutter PHD is
``c(z) = clutter_rate / |area|`` inside it. The pose is ignored (the sensor sees the whole area);
it satisfies :class:`searchtrack.models.particle_models.DetectionSensor`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray

TAIL_SIGMAS = 9.0


def area_array(name: str, area: ArrayLike) -> FloatArray:
    """``area`` ``[[x0, x1], [y0, y1]]`` as a read-only ``(2, 2)`` array, ``x0 < x1, y0 < y1``."""
    arr = checks.finite_array(name, area, (2, 2))
    if not np.all(arr[:, 1] > arr[:, 0]):
        raise InvalidInputError(name, area, "must be [[x0, x1], [y0, y1]] with x0 < x1, y0 < y1")
    return arr


@dataclass(frozen=True)
class PositionSensor:
    """Detects targets inside ``area`` with probability ``pd`` and measures their 2-D position.

    Parameters
    ----------
    pd
        Detection probability inside the area, in ``[0, 1]`` (0 outside).
    sigma_m
        Standard deviation of the position noise per axis (m), ``> 0``.
    clutter_rate
        Mean number of false alarms per scan, ``≥ 0``.
    area
        ``[[x0, x1], [y0, y1]]`` (m).
    """

    pd: float
    sigma_m: float
    clutter_rate: float
    area: FloatArray

    def __post_init__(self) -> None:
        object.__setattr__(self, "pd", checks.real("pd", self.pd, low=0.0, high=1.0))
        object.__setattr__(self, "sigma_m", checks.positive("sigma_m", self.sigma_m))
        object.__setattr__(self, "clutter_rate",
                           checks.non_negative("clutter_rate", self.clutter_rate))
        object.__setattr__(self, "area", area_array("area", self.area))

    @property
    def meas_dim(self) -> int:
        """Measurements are ``[x, y]``."""
        return 2

    @property
    def area_m2(self) -> float:
        """Size of the area (m²)."""
        return float(np.prod(self.area[:, 1] - self.area[:, 0]))

    def inside(self, positions: FloatArray) -> NDArray[np.bool_]:
        """``(N,)`` whether each ``(N, ≥2)`` position lies in the area (edges included)."""
        xy = positions[:, :2]
        return np.asarray(np.all((xy >= self.area[:, 0]) & (xy <= self.area[:, 1]), axis=1))

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N,)`` ``pd`` inside the area, 0 outside."""
        return np.where(self.inside(positions), self.pd, 0.0)

    def likelihood(self, pose: FloatArray, measurements: FloatArray,
                   positions: FloatArray) -> FloatArray:
        """``(k, N)`` Gaussian densities ``N(z_i; x_j, σ² I)``.

        Beyond ``TAIL_SIGMAS`` standard deviations the density is held at its value there
        (``e^{-40.5}`` of the peak), which keeps ``exp`` out of its slow subnormal range.
        """
        s2 = self.sigma_m**2
        e = measurements[:, 0:1] - positions[:, 0]
        e *= e
        dy = measurements[:, 1:2] - positions[:, 1]
        dy *= dy
        e += dy
        e *= -0.5 / s2
        np.maximum(e, -0.5 * TAIL_SIGMAS**2, out=e)
        np.exp(e, out=e)
        e *= 1.0 / (2.0 * math.pi * s2)
        return e

    def clutter_intensity(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k,)`` clutter PHD ``clutter_rate / |area|`` inside the area, 0 outside."""
        return np.where(self.inside(measurements), self.clutter_rate / self.area_m2, 0.0)

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """The measurements themselves: ``h`` is the identity."""
        return np.array(measurements[:, :2], dtype=np.float64)

    def measure(self, positions: FloatArray,
                rng: np.random.Generator) -> tuple[FloatArray, NDArray[np.int64]]:
        """One simulated scan of targets at ``(N, ≥2)`` positions.

        Returns
        -------
        (measurements, origin)
            ``(k, 2)`` detections in random order, and ``(k,)`` the index of the target behind
            each one (``-1`` for clutter).
        """
        pos = np.asarray(positions, dtype=np.float64).reshape(-1, positions.shape[-1])
        hit = self.inside(pos) & (rng.random(pos.shape[0]) < self.pd)
        idx = np.flatnonzero(hit)
        det = pos[idx, :2] + self.sigma_m * rng.standard_normal((idx.size, 2))
        n_clutter = int(rng.poisson(self.clutter_rate))
        lo, hi = self.area[:, 0], self.area[:, 1]
        clutter = lo + (hi - lo) * rng.random((n_clutter, 2))
        z = np.vstack([det, clutter])
        origin = np.concatenate([idx, np.full(n_clutter, -1)]).astype(np.int64)
        order = rng.permutation(z.shape[0])
        return z[order], origin[order]
