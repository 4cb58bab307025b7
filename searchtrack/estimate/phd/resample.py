"""Low-variance (systematic) resampling of a particle PHD with a particle cap.

Thrun, Burgard & Fox 2005, Table 4.4: one uniform offset, ``N'`` evenly spaced pointers into the
cumulative normalized weights. The new particle count is
``N' = clip(round(particles_per_target · λ), min_particles, max_particles)`` and every new weight
is ``λ / N'``, so the total mass ``λ`` is kept exactly (paper 004, eq. A7). The ``"numba"``
backend finds the same ancestors by one merge of the sorted pointers and copies each chosen
particle once (:func:`searchtrack.estimate.phd.compiled.systematic`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.types import IntArray
from searchtrack.estimate.phd import compiled
from searchtrack.estimate.phd.config import PHDConfig
from searchtrack.estimate.phd.state import PHDState


def systematic_indices(weights: NDArray[np.float64], n: int,
                       rng: np.random.Generator) -> IntArray:
    """``n`` ancestor indices drawn by systematic resampling from non-negative ``weights``."""
    cum = np.cumsum(weights)
    total = cum[-1]
    pointers = (rng.random() + np.arange(n)) * (total / n)
    idx = np.searchsorted(cum, pointers, side="right")
    return np.asarray(np.minimum(idx, weights.shape[0] - 1), dtype=np.int64)


def resample(state: PHDState, config: PHDConfig, rng: np.random.Generator) -> PHDState:
    """Equal-weight particles carrying the same total mass; the update records are kept."""
    mass = state.expected_count()
    if state.n_particles == 0 or mass <= 0.0:
        return state.select(np.zeros(state.n_particles, dtype=bool))
    n = round(config.particles_per_target * mass)
    n = min(max(n, config.min_particles), config.max_particles)
    if config.backend == "numba":
        x, labels, tags = compiled.systematic(state.weights, n, float(rng.random()),
                                              state.states, state.labels, state.tags)
        return PHDState(x, np.full(n, mass / n), labels, tags, state.position_dim, state.record)
    idx = systematic_indices(state.weights, n, rng)
    return state.select(idx, np.full(n, mass / n))
