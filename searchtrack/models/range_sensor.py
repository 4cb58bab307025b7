"""An omnidirectional 3-D ranging sensor with an exponential field of view (paper 004, eqs. 1–3).

Detection probability, eq. (1)::

    π(x, q) = G · exp(−‖ζ‖ / 2),   ζ = ((x − q_x)/F_x, (y − q_y)/F_y, (z − q_z)/F_z)

printed with the norm *not* squared; ``squared=True`` uses ``exp(−‖ζ‖² / 2)``, a Gaussian field
of view. Measurement, eq. (2)::

    h(x) = [d, θ, ϖ],  d = ‖x − q‖,  θ = atan2(y − q_y, x − q_x),  ϖ = arcsin((z − q_z) / d)

with noise ``N(0, diag(σ_d², σ_θ², σ_ϖ²))`` (the paper prints one ``σ`` for metres and radians;
a scalar ``sigma`` gives that). Likelihood, eq. (3): ``g(z | x) = N(z; h(x), R)`` with the
bearing residual wrapped to ``[−π, π)``. The inverse map (not printed; standard
spherical to Cartesian) is ``h⁻¹(z) = q + d [cos ϖ cos θ, cos ϖ sin θ, sin ϖ]``.

The paper has no clutter; ``clutter_rate > 0`` adds Poisson clutter uniform over the measurement
box ``[0, max_range_m] × [−π, π) × [−π/2, π/2]``. Positions are 3-D; the pose is ``[x, y, z, ...]``
(further entries ignored).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.angles import wrap_angle
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


def _pose(pose: FloatArray) -> FloatArray:
    arr = np.asarray(pose, dtype=np.float64).reshape(-1)
    if arr.size < 3 or not np.all(np.isfinite(arr[:3])):
        raise InvalidInputError("pose", pose, "must start with a finite position [x, y, z]")
    return arr[:3]


def _positions(positions: FloatArray) -> FloatArray:
    arr = np.asarray(positions, dtype=np.float64)
    if arr.ndim != 2 or arr.shape[1] < 3:
        raise InvalidInputError("positions", arr.shape, "must have shape (N, 3)")
    return arr[:, :3]


def _triple(name: str, value: ArrayLike) -> FloatArray:
    """Three positive numbers (a scalar is repeated)."""
    arr = np.broadcast_to(np.asarray(value, dtype=np.float64), (3,)) if np.ndim(value) == 0 \
        else np.asarray(value, dtype=np.float64)
    arr = checks.finite_array(name, arr, (3,))
    if not np.all(arr > 0.0):
        raise InvalidInputError(name, value, "must be > 0")
    return arr


@dataclass(frozen=True)
class RangeBearingElevationSensor:
    """Range–bearing–elevation sensor with the exponential field of view of paper 004.

    Parameters
    ----------
    gain
        ``G``, the detection probability at the sensor, in ``(0, 1]``.
    fov_m
        ``(F_x, F_y, F_z)`` (m), the size of the probabilistic field of view, each ``> 0`` (a
        scalar gives a spherical field of view).
    sigma
        ``(σ_d [m], σ_θ [rad], σ_ϖ [rad])`` noise standard deviations, each ``> 0`` (a scalar is
        the paper's ``R = σ² I``).
    squared
        Use ``exp(−‖ζ‖²/2)`` instead of the printed ``exp(−‖ζ‖/2)``.
    clutter_rate
        Mean false alarms per scan, ``≥ 0`` (0, the paper's assumption, by default).
    max_range_m
        Range limit of the clutter box (m), ``> 0``.
    """

    gain: float = 1.0
    fov_m: ArrayLike = 10.0
    sigma: ArrayLike = 1.0
    squared: bool = False
    clutter_rate: float = 0.0
    max_range_m: float = 1000.0

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "gain", checks.real("gain", self.gain, low=0.0, high=1.0, low_open=True))
        set_(self, "fov_m", _triple("fov_m", self.fov_m))
        set_(self, "sigma", _triple("sigma", self.sigma))
        checks.boolean("squared", self.squared)
        set_(self, "clutter_rate", checks.non_negative("clutter_rate", self.clutter_rate))
        set_(self, "max_range_m", checks.positive("max_range_m", self.max_range_m))

    @property
    def meas_dim(self) -> int:
        """Measurements are ``[d, θ, ϖ]``."""
        return 3

    @property
    def _fov(self) -> FloatArray:
        return np.asarray(self.fov_m, dtype=np.float64)

    @property
    def _sigma(self) -> FloatArray:
        return np.asarray(self.sigma, dtype=np.float64)

    @property
    def measurement_volume(self) -> float:
        """Size of the clutter box ``max_range_m · 2π · π`` (m·rad²)."""
        return self.max_range_m * 2.0 * math.pi * math.pi

    def detection_probability(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N,)`` ``π(x, q)``, eq. (1)."""
        zeta = (_positions(positions) - _pose(pose)) / self._fov
        n2 = np.sum(zeta * zeta, axis=1)
        return np.asarray(self.gain * np.exp(-0.5 * (n2 if self.squared else np.sqrt(n2))))

    def measurement(self, pose: FloatArray, positions: FloatArray) -> FloatArray:
        """``(N, 3)`` noise-free ``h(x) = [d, θ, ϖ]``, eq. (2) (``ϖ = 0`` at the sensor)."""
        rel = _positions(positions) - _pose(pose)
        d = np.sqrt(np.sum(rel * rel, axis=1))
        safe = np.where(d > 0.0, d, 1.0)
        theta = np.arctan2(rel[:, 1], rel[:, 0])
        elev = np.arcsin(np.clip(rel[:, 2] / safe, -1.0, 1.0))
        return np.column_stack([d, theta, elev])

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k, 3)`` positions ``h⁻¹(z) = q + d [cos ϖ cos θ, cos ϖ sin θ, sin ϖ]``."""
        z = np.asarray(measurements, dtype=np.float64).reshape(-1, 3)
        d, theta, elev = z[:, 0], z[:, 1], z[:, 2]
        ce = np.cos(elev)
        unit = np.column_stack([ce * np.cos(theta), ce * np.sin(theta), np.sin(elev)])
        return np.asarray(_pose(pose) + d[:, None] * unit)

    @staticmethod
    def _residuals(measurements: FloatArray, predicted: FloatArray) -> FloatArray:
        """``(k, N, 3)`` residuals ``z_i − h(x_j)`` against the ``(N, 3)`` ``predicted``
        ``h(x_j)``, bearing wrapped to ``[−π, π)``."""
        z = np.asarray(measurements, dtype=np.float64).reshape(-1, 3)
        res = z[:, None, :] - predicted[None, :, :]
        res[:, :, 1] = wrap_angle(res[:, :, 1])
        return res

    def likelihood(self, pose: FloatArray, measurements: FloatArray,
                   positions: FloatArray) -> FloatArray:
        """``(k, N)`` densities ``N(z_i; h(x_j), R)``, eq. (3), bearing residual wrapped."""
        s = self._sigma
        res = self._residuals(measurements, self.measurement(pose, positions))
        res /= s
        norm = 1.0 / ((2.0 * math.pi) ** 1.5 * float(np.prod(s)))
        return np.asarray(norm * np.exp(-0.5 * np.sum(res * res, axis=2)))

    def innovation_distance(self, pose: FloatArray, measurements: FloatArray,
                            positions: FloatArray, position_sigma_m: float = 0.0) -> FloatArray:
        """``(k, N)`` normalised innovations ``‖S^{-1/2} (z_i − h(x_j))‖`` (Mahalanobis).

        ``S = R + H P Hᵀ`` with ``P = s² I`` the isotropic uncertainty of the position ``x_j``
        (``s = position_sigma_m ≥ 0``) and ``H`` the Jacobian of ``h`` at ``x_j``, whose rows
        (range, bearing, elevation) are orthogonal with norms ``1``, ``1/(d cos ϖ)`` and
        ``1/d``: ``S = diag(σ_d² + s², σ_θ² + s²/(d cos ϖ)², σ_ϖ² + s²/d²)``. With ``s = 0`` this
        is the distance in standard deviations of the noise of eq. (2); the position noise of a
        measurement grows with the range (``σ_θ d`` across the line of sight), which a fixed
        gate in metres ignores.
        """
        s2 = checks.non_negative("position_sigma_m", position_sigma_m) ** 2
        h = self.measurement(pose, positions)
        d = np.maximum(h[:, 0], 1e-9)
        cos_e = np.maximum(np.cos(h[:, 2]), 1e-9)
        var = np.column_stack([np.ones_like(d), 1.0 / (d * cos_e) ** 2, 1.0 / d ** 2]) * s2
        var += self._sigma ** 2
        res = self._residuals(measurements, h)
        return np.asarray(np.sqrt(np.sum(res * res / var[None, :, :], axis=2)))

    def clutter_intensity(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k,)`` clutter PHD ``clutter_rate / volume`` inside the measurement box (0 without
        clutter)."""
        z = np.asarray(measurements, dtype=np.float64).reshape(-1, 3)
        inside = (z[:, 0] >= 0.0) & (z[:, 0] <= self.max_range_m)
        return np.where(inside, self.clutter_rate / self.measurement_volume, 0.0)

    def measure(self, pose: FloatArray, positions: FloatArray,
                rng: np.random.Generator) -> tuple[FloatArray, NDArray[np.int64]]:
        """One simulated scan: each target detected with ``π`` (``b ~ Bernoulli(π)``), measured
        with noise (bearing wrapped), plus clutter.

        Returns
        -------
        (measurements, origin)
            ``(k, 3)`` measurements in random order and ``(k,)`` target indices (``-1``: clutter).
        """
        rng = checks.generator("rng", rng)
        pos = _positions(positions)
        pi = self.detection_probability(pose, pos)
        idx = np.flatnonzero(rng.random(pi.size) < pi)
        det = self.measurement(pose, pos[idx]) + self._sigma * rng.standard_normal((idx.size, 3))
        det[:, 1] = wrap_angle(det[:, 1])
        n_clutter = int(rng.poisson(self.clutter_rate))
        u = rng.random((n_clutter, 3))
        clutter = np.column_stack([u[:, 0] * self.max_range_m, (u[:, 1] - 0.5) * 2.0 * math.pi,
                                   (u[:, 2] - 0.5) * math.pi])
        z = np.vstack([det, clutter])
        origin = np.concatenate([idx, np.full(n_clutter, -1)]).astype(np.int64)
        order = rng.permutation(z.shape[0])
        return z[order], origin[order]
