"""Entropy per target of a particle PHD (paper 003, eqs. 14–15).

For a Poisson RFS of intensity ``v`` with ``λ = ∫ v`` and single-target density ``p = v / λ``,
``H[X] = λ + λ (H[p] − log λ)``; the bracket ``H[p] − log λ`` is the *entropy per target* plotted
in paper 003. ``H[p]`` is the differential entropy of ``p``, estimated from a weighted histogram
on a regular grid: ``H[p] ≈ −Σ_k p_k log(p_k / A)`` with cell probability ``p_k`` and cell size
``A`` (m² or m³). Its value depends on the length unit and the cell size (paper 003 states
neither), so compare values only at equal settings.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.particle_belief import ParticleBelief


def entropy_per_target(belief: ParticleBelief, bounds: ArrayLike, cell_m: float) -> float:
    """``H[p] − log λ`` (nats) on a grid of ``cell_m`` cells over ``bounds`` (``(p, 2)``, m).

    Particles outside ``bounds`` count in the nearest edge cell. Returns ``nan`` when ``λ = 0``.

    Raises
    ------
    InvalidInputError
        If ``bounds`` does not match the particles' dimension or ``cell_m`` is not positive.
    """
    cell = checks.positive("cell_m", cell_m)
    pos, w = belief.positions, belief.weights
    b = np.asarray(bounds, dtype=np.float64)
    p = pos.shape[1]
    if b.shape != (p, 2) or not np.all(b[:, 1] > b[:, 0]):
        raise InvalidInputError("bounds", bounds, f"must be ({p}, 2) with low < high")
    lam = float(w.sum())
    if lam <= 0.0:
        return math.nan
    shape = np.maximum(np.ceil((b[:, 1] - b[:, 0]) / cell).astype(np.int64), 1)
    idx = np.floor((pos - b[:, 0]) / cell).astype(np.int64)
    idx = np.clip(idx, 0, shape - 1)
    flat = np.ravel_multi_index(tuple(idx.T), tuple(shape))
    prob = np.bincount(flat, weights=w) / lam
    prob = prob[prob > 0.0]
    h = float(-(prob * np.log(prob / cell**p)).sum())
    return h - math.log(lam)
