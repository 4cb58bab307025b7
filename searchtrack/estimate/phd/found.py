"""Found-target bookkeeping of paper 004 (§4.2, Algorithm 1 lines 1–14).

A k-means cluster that is narrow (radius ``≤ T_r``) and heavy (mass ``≥ T_m``) is a *found*
target: its centre is saved and all its particles are removed from the PHD, so the planner stops
spending effort on it. Before each update, measurements are gated against the found targets: for
each found target (in the order they were found) the closest not-yet-removed measurement within
``T_z`` of it (in position space, through ``h⁻¹``) is dropped, since a target yields at most one
measurement per scan. The cluster radius is the weighted RMS distance to the centre (paper 004
does not define it).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.phd.extract import Clusters
from searchtrack.estimate.phd.state import PHDState


@dataclass(frozen=True)
class FoundConfig:
    """Thresholds ``T_r`` (m), ``T_m`` and ``T_z`` (m); paper 004 simulations: 1.1, 2.2, 5."""

    radius_m: float = 1.1
    mass: float = 2.2
    gate_m: float = 5.0

    def __post_init__(self) -> None:
        for name in ("radius_m", "mass", "gate_m"):
            object.__setattr__(self, name, checks.positive(name, getattr(self, name)))


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


def gate_measurements(found: FloatArray, positions: FloatArray, gate_m: float) -> NDArray[np.bool_]:
    """``(k,)`` mask of measurements to keep: each found target removes its closest measurement
    position within ``gate_m`` (one per found target, found targets taken in order)."""
    keep = np.ones(positions.shape[0], dtype=bool)
    if positions.shape[0] == 0:
        return keep
    for x in found:
        dist = np.linalg.norm(positions - x, axis=1)
        dist[~keep] = np.inf
        i = int(np.argmin(dist))
        if dist[i] <= gate_m:
            keep[i] = False
    return keep
