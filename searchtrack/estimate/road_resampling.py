"""Low-variance (systematic) resampling of many particle filters at once (Moore et al. 2021, §2.1).

Systematic resampling (Thrun, Burgard and Fox 2006): one ``r ~ U(0, 1/N)`` per filter, and
particle ``j`` of the output copies the input particle whose cumulative weight first exceeds
``r + j/N``. With equal weights it is the identity, so a filter whose weights are uniform never
needs it. :func:`systematic_indices` is the NumPy form for a ``(B, N)`` batch (one
``np.searchsorted`` over offset cumulative sums); the filters use the equivalent numba kernel
:func:`~searchtrack.estimate.road_filter_kernels.resample_rows` in place.

:class:`ResamplePolicy` says when: after every update (the paper's code and the assumption of its
Lemma 2), or selectively when the effective sample size ``N_eff = 1 / Σ w²`` (Eq. 5) falls
below ``threshold · N`` (Grisetti et al. 2005; the paper's example is ``2N/3``), the weights
accumulating in between (Eq. 6).

:class:`SpeedRoughening` (beyond the paper) roughens the speed state of the drive-and-stop
particles (:class:`~searchtrack.models.road_particles.CourierRoadMotion`) after a resampling of
the weights (Gordon, Salmond and Smith 1993). Those particles drive without per-step noise, so
the copies a resampling makes of one particle would drive on as one for as long as they drive:
a cloud seen for a while collapses onto a few speeds, and a cloud thinned by negative
information onto a few clumps, each a node-belief peak where the target need not be. Each
driving particle's speed moves by a Gaussian of Silverman's bandwidth
``h = c · 1.06 · σ̂_v · n^{-1/5}`` of its row's ``n`` driving speeds (spread ``σ̂_v``),
reflected into the drive-speed range; stopped particles keep 0. A cloud that has learned its
target's speed (small ``σ̂_v``) is barely moved; copies part at about ``h``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import BoolArray, FloatArray, IntArray


@dataclass(frozen=True)
class ResamplePolicy:
    """When a particle filter resamples.

    Parameters
    ----------
    threshold
        ``None``: after every update. A number ``q`` in ``(0, 1]``: only when
        ``N_eff < q · N`` (Eq. 5), e.g. ``2/3``.
    """

    threshold: float | None = None

    def __post_init__(self) -> None:
        if self.threshold is not None:
            object.__setattr__(self, "threshold", checks.real(
                "threshold", self.threshold, low=0.0, high=1.0, low_open=True))

    def due(self, w: FloatArray) -> BoolArray:
        """For each row of normalized weights ``(B, N)``: whether to resample it now."""
        if self.threshold is None:
            return np.ones(w.shape[0], dtype=bool)
        return np.asarray(effective_sample_size(w) < self.threshold * w.shape[1])


#: The factor of Silverman's rule of thumb for a Gaussian kernel.
SILVERMAN = 1.06


@dataclass(frozen=True)
class SpeedRoughening:
    """Roughening of the particles' speeds after each resampling (module docstring).

    Parameters
    ----------
    scale
        ``c``, the factor on Silverman's bandwidth, > 0 (1: the rule itself).
    """

    scale: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "scale", checks.positive("scale", self.scale))

    def bandwidths(self, v: FloatArray) -> FloatArray:
        """``(B,)`` bandwidth ``h`` (m/s) of each row of speeds ``(B, N)`` (0 for a row with
        fewer than two driving particles)."""
        drive = v > 0.0
        n = drive.sum(axis=1)
        mean = np.where(drive, v, 0.0).sum(axis=1) / np.maximum(n, 1)
        var = np.where(drive, (v - mean[:, None]) ** 2, 0.0).sum(axis=1) / np.maximum(n - 1, 1)
        h = self.scale * SILVERMAN * np.sqrt(var) * np.maximum(n, 1) ** -0.2
        return np.asarray(np.where(n >= 2, h, 0.0), dtype=np.float64)

    def roughen(self, v: FloatArray, rows: IntArray, low_mps: float, high_mps: float,
                rng: np.random.Generator) -> None:
        """Roughen ``rows`` of the speeds ``v`` ``(F, N)`` in place, reflecting into
        ``[low_mps, high_mps]``; one standard normal per particle of those rows."""
        if rows.size == 0:
            return
        block = v[rows]
        moved = block + self.bandwidths(block)[:, None] * rng.standard_normal(block.shape)
        v[rows] = np.where(block > 0.0, reflect(moved, low_mps, high_mps), block)


def reflect(x: FloatArray, low: float, high: float) -> FloatArray:
    """``x`` folded into ``[low, high]`` by reflection at both ends (``low`` if they meet)."""
    width = high - low
    if width <= 0.0:
        return np.full_like(x, low)
    y = np.mod(x - low, 2.0 * width)
    return np.asarray(low + np.where(y > width, 2.0 * width - y, y), dtype=np.float64)


def effective_sample_size(w: ArrayLike) -> FloatArray:
    """Eq. 5: ``N_eff = 1 / Σ_n (w^n)²`` of each row of normalized weights ``(..., N)``."""
    arr = np.asarray(w, dtype=np.float64)
    return np.asarray(1.0 / np.einsum("...n,...n->...", arr, arr), dtype=np.float64)


def systematic_indices(w: ArrayLike, u: ArrayLike) -> IntArray:
    """Systematic resampling of each row of ``w`` ``(B, N)`` with offsets ``u`` ``(B,)`` in
    ``[0, 1)``: ``(B, N)`` indices, row ``b`` drawn at cumulative weights ``(u_b + j) / N``.

    Rows need not be normalized but must have a positive sum.

    Raises
    ------
    InvalidInputError
        ``w`` not a finite non-negative ``(B, N)`` array with positive row sums, or ``u`` not
        ``(B,)`` in ``[0, 1)``.
    """
    weights = checks.finite_array("w", w, (None, None))
    b, n = weights.shape
    offsets = checks.finite_array("u", u, (b,))
    totals = weights.sum(axis=1)
    if np.any(weights < 0.0) or np.any(totals <= 0.0):
        raise InvalidInputError("w", weights.shape, "rows must be non-negative with a positive sum")
    if np.any(offsets < 0.0) or np.any(offsets >= 1.0):
        raise InvalidInputError("u", u, "must lie in [0, 1)")
    rows = np.arange(b)
    cum = np.cumsum(weights / totals[:, None], axis=1)
    cum[:, -1] = 1.0
    cum += rows[:, None]
    targets = rows[:, None] + (offsets[:, None] + np.arange(n)) / n
    flat = np.searchsorted(cum.ravel(), targets.ravel(), side="right")
    idx = np.minimum(flat.reshape(b, n) - rows[:, None] * n, n - 1)
    return np.asarray(np.maximum(idx, 0), dtype=np.int64)
