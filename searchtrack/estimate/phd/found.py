"""Found-target bookkeeping of paper 004 (§4.2, Algorithm 1 lines 1–14).

A k-means cluster that is narrow (radius ``≤ T_r``) and heavy (mass ``≥ T_m``) is a *found*
target: its centre is saved and all its particles are removed from the PHD, so the planner stops
spending effort on it. Before each update, measurements are gated against the found targets: for
each found target (in the order they were found) the closest not-yet-removed measurement within
``T_z`` of it (in position space, through ``h⁻¹``) is dropped, since a target yields at most one
measurement per scan. The cluster radius is the weighted RMS distance to the centre (paper 004
does not define it).

The gate serves, in 004's words, to prevent "re-formation of an intensity peak at found targets".
A ball of ``T_z`` metres does so only while the sensor's position noise is well inside it. With a
ranging sensor the noise across the line of sight grows with the range (``σ_θ d``: 2 m per axis
at 100 m for ``σ_θ = 0.02`` rad), so a found target's far detections leave a 5 m ball, are taken
for a new target and rebuild its peak. ``FoundConfig.gate_sigmas > 0`` gates instead on the
normalised innovation ``z − h(x̂)`` of each found target ``x̂``, with covariance ``R + H P Hᵀ``:
the sensor noise plus an isotropic position uncertainty ``P = (T_z / g)² I`` of ``x̂``. With a
noise-free sensor that gate is the ``T_z`` ball; the noise widens it with the range.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.phd.extract import Clusters
from searchtrack.estimate.phd.state import PHDState
from searchtrack.models.particle_models import DetectionSensor


@runtime_checkable
class InnovationSensor(Protocol):
    """A sensor that can say how many standard deviations a measurement lies from a position
    (e.g. :class:`~searchtrack.models.range_sensor.RangeBearingElevationSensor`)."""

    def innovation_distance(self, pose: FloatArray, measurements: FloatArray,
                            positions: FloatArray, position_sigma_m: float = 0.0) -> FloatArray:
        """``(k, N)`` normalised innovations of ``k`` measurements against ``N`` positions whose
        own uncertainty is isotropic with standard deviation ``position_sigma_m``."""
        ...

    def to_position(self, pose: FloatArray, measurements: FloatArray) -> FloatArray:
        """``(k, p)`` positions ``h⁻¹(z)``."""
        ...


@dataclass(frozen=True)
class FoundConfig:
    """Thresholds ``T_r`` (m), ``T_m`` and ``T_z`` (m); paper 004 simulations: 1.1, 2.2, 5.

    ``gate_sigmas`` (``g ≥ 0``) chooses the measurement gate of :func:`gate_found`: 0 (default)
    is the printed ball of ``T_z`` metres; ``g > 0`` gates on the normalised innovation, within
    ``g`` standard deviations of the sensor noise plus a position uncertainty ``T_z / g`` of the
    found target (see the module docstring).
    """

    radius_m: float = 1.1
    mass: float = 2.2
    gate_m: float = 5.0
    gate_sigmas: float = 0.0

    def __post_init__(self) -> None:
        for name in ("radius_m", "mass", "gate_m"):
            object.__setattr__(self, name, checks.positive(name, getattr(self, name)))
        object.__setattr__(self, "gate_sigmas",
                           checks.non_negative("gate_sigmas", self.gate_sigmas))


def mark_found(state: PHDState, clusters: Clusters, config: FoundConfig,
               found: FloatArray) -> tuple[PHDState, FloatArray]:
    """Save narrow, heavy clusters as found and remove their particles.

    Parameters
    ----------
    state
        The PHD the clusters were computed on.
    clusters
        Its weighted k-means clusters.
    config
        The thresholds.
    found
        ``(m, position_dim)`` targets found so far.

    Returns
    -------
    (state, found)
        The PHD without the found clusters' particles, and ``found`` with the new centres
        appended.
    """
    if clusters.members.shape[0] != state.n_particles:
        raise InvalidInputError("clusters", clusters.members.shape[0],
                                f"must partition the state's {state.n_particles} particles")
    p = state.position_dim
    hit = (clusters.radii_m <= config.radius_m) & (clusters.masses >= config.mass)
    if not np.any(hit):
        return state, found
    keep = ~np.append(hit, False)[clusters.members]  # member -1 (outlier) is kept
    new = state.select(keep)
    return new, np.vstack([found.reshape(-1, p), clusters.centres[hit, :p]])


def _remove_closest(distances: FloatArray, limit: float) -> NDArray[np.bool_]:
    """``(k,)`` keep-mask: for each row of the ``(m, k)`` ``distances`` in order, the closest
    measurement not yet removed, if within ``limit``, is removed."""
    keep = np.ones(distances.shape[1], dtype=bool)
    for row in distances:
        dist = np.where(keep, row, np.inf)
        i = int(np.argmin(dist))
        if dist[i] <= limit:
            keep[i] = False
    return keep


def gate_measurements(found: FloatArray, positions: FloatArray, gate_m: float) -> NDArray[np.bool_]:
    """``(k,)`` mask of measurements to keep: each found target removes its closest measurement
    position within ``gate_m`` (one per found target, found targets taken in order)."""
    if positions.shape[0] == 0 or found.shape[0] == 0:
        return np.ones(positions.shape[0], dtype=bool)
    dist = np.linalg.norm(positions[None, :, :] - found[:, None, :], axis=2)
    return _remove_closest(dist, gate_m)


def gate_found(found: FloatArray, sensor: DetectionSensor, pose: FloatArray,
               measurements: FloatArray, config: FoundConfig) -> NDArray[np.bool_]:
    """``(k,)`` mask of ``measurements`` to keep after gating against the ``found`` targets.

    With ``config.gate_sigmas = 0`` this is :func:`gate_measurements` on ``h⁻¹(z)`` with
    ``T_z`` (004, Algorithm 1 lines 9–12); otherwise each found target in order removes the
    not-yet-removed measurement of smallest normalised innovation (``sensor`` must be an
    :class:`InnovationSensor`) if it is within ``gate_sigmas``, the innovation covariance
    including a position uncertainty ``T_z / gate_sigmas`` of the found target.

    Raises
    ------
    InvalidInputError
        ``gate_sigmas > 0`` with a sensor that has no ``innovation_distance``.
    """
    z = np.asarray(measurements, dtype=np.float64)
    if found.shape[0] == 0 or z.shape[0] == 0:
        return np.ones(z.shape[0], dtype=bool)
    if config.gate_sigmas == 0.0:
        return gate_measurements(found, sensor.to_position(pose, z), config.gate_m)
    if not isinstance(sensor, InnovationSensor):
        raise InvalidInputError("sensor", type(sensor).__name__,
                                "must have innovation_distance when gate_sigmas > 0")
    dist = sensor.innovation_distance(pose, z, found, config.gate_m / config.gate_sigmas)
    return _remove_closest(dist.T, config.gate_sigmas)
