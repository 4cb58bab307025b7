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

:class:`KLDSampling` (beyond the paper) lets the number of particles of each cloud follow its
spread (Fox 2003, "Adapting the sample size in particle filters through KLD-sampling"): with
``k`` the road bins the posterior occupies, ``n(k) = χ²_{k−1, 1−δ} / (2ε)`` particles bound the
Kullback-Leibler divergence between the sample-based and the true (binned) posterior by ``ε``
with probability ``1 − δ`` (bins over the road, and over the speed when the particles carry
one and ``speed_bin_mps`` is set); the chi-square quantile is Wilson and Hilferty's,
``n(k) ≈ (k−1)/(2ε) · (1 − 2/(9(k−1)) + z_{1−δ} √(2/(9(k−1))))³``. A cloud on its target
(a few bins) keeps a few hundred particles; a cloud spread over a city takes the cap. Fox draws
particles one at a time until their count reaches the bound of the bins they fill; here a
resampling draws the cap's systematic sample, counts the bins it fills, and draws
``clip(n(k), n_min, cap)`` systematically from the same weights (the bins of the cap's sample
are at least those of the smaller one, so the count errs on the side of more particles). A cloud
of ``n`` particles keeps them in its first ``n`` columns with weights ``1/n``; the columns
beyond weigh 0 and every kernel skips them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from statistics import NormalDist

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

    def due(self, w: FloatArray, count: IntArray | None = None) -> BoolArray:
        """For each row of normalized weights ``(B, N)``: whether to resample it now
        (``count`` ``(B,)``: the particles each row holds, ``N`` if ``None``)."""
        if self.threshold is None:
            return np.ones(w.shape[0], dtype=bool)
        n = w.shape[1] if count is None else count
        return np.asarray(effective_sample_size(w) < self.threshold * n)


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

    def bandwidths(self, v: FloatArray, count: IntArray | None = None) -> FloatArray:
        """``(B,)`` bandwidth ``h`` (m/s) of each row of speeds ``(B, N)`` (0 for a row with
        fewer than two driving particles); ``count`` ``(B,)``: only each row's first ``count``
        particles are read (all if ``None``)."""
        drive = v > 0.0
        if count is not None:
            drive &= np.arange(v.shape[1]) < np.asarray(count)[:, None]
        n = drive.sum(axis=1)
        mean = np.where(drive, v, 0.0).sum(axis=1) / np.maximum(n, 1)
        var = np.where(drive, (v - mean[:, None]) ** 2, 0.0).sum(axis=1) / np.maximum(n - 1, 1)
        h = self.scale * SILVERMAN * np.sqrt(var) * np.maximum(n, 1) ** -0.2
        return np.asarray(np.where(n >= 2, h, 0.0), dtype=np.float64)

    def roughen(self, v: FloatArray, rows: IntArray, low_mps: float, high_mps: float,
                rng: np.random.Generator, count: IntArray | None = None) -> None:
        """Roughen ``rows`` of the speeds ``v`` ``(F, N)`` in place, reflecting into
        ``[low_mps, high_mps]``; one standard normal per particle of those rows (``count``
        ``(F,)``: the particles each row holds, for the bandwidths)."""
        if rows.size == 0:
            return
        block = v[rows]
        live = None if count is None else np.asarray(count)[rows]
        moved = block + self.bandwidths(block, live)[:, None] * rng.standard_normal(block.shape)
        v[rows] = np.where(block > 0.0, reflect(moved, low_mps, high_mps), block)


@dataclass(frozen=True)
class KLDSampling:
    """Particle counts that follow each cloud's spread (module docstring).

    Parameters
    ----------
    epsilon
        ``ε``, the bound on the Kullback-Leibler divergence, in ``(0, 1)``.
    quantile
        ``1 − δ``, the probability the bound holds, in ``(0.5, 1)``.
    bin_m
        Bin length (m) along each directed edge, > 0.
    min_particles
        Fewest particles a cloud keeps, ≥ 2 (a cloud of one bin needs no more).
    speed_bin_mps
        Width (m/s) of the speed bins each road bin is cut into when the particles carry a
        speed (:class:`~searchtrack.models.road_particles.CourierRoadMotion`), > 0; ``None``:
        road bins alone.
    """

    epsilon: float = 0.05
    quantile: float = 0.99
    bin_m: float = 10.0
    min_particles: int = 50
    speed_bin_mps: float | None = None

    def __post_init__(self) -> None:
        checks.real("epsilon", self.epsilon, low=0.0, high=1.0, low_open=True, high_open=True)
        checks.real("quantile", self.quantile, low=0.5, high=1.0, low_open=True, high_open=True)
        checks.positive("bin_m", self.bin_m)
        checks.count("min_particles", self.min_particles, least=2)
        if self.speed_bin_mps is not None:
            checks.positive("speed_bin_mps", self.speed_bin_mps)

    def speed_bins(self, max_speed_mps: float | None) -> int:
        """Speed bins per road bin for particles of speeds in ``[0, max_speed_mps]``
        (``None``: no speed state, one bin)."""
        if self.speed_bin_mps is None or max_speed_mps is None:
            return 1
        return math.floor(max_speed_mps / self.speed_bin_mps) + 1

    def bound(self, bins: int) -> float:
        """``n(k)`` for ``k = bins`` occupied bins (Wilson-Hilferty; 0 for ``k ≤ 1``)."""
        return _kld_bound(bins, self.epsilon, NormalDist().inv_cdf(self.quantile))

    def table(self, cap: int) -> IntArray:
        """``(cap + 1,)``: the particles a resampled cloud keeps when its cap-sized systematic
        sample fills ``k`` bins, ``clip(⌈n(k)⌉, min_particles, cap)`` at index ``k``."""
        n = checks.count("cap", cap, least=1)
        z = NormalDist().inv_cdf(self.quantile)
        out = [min(max(math.ceil(_kld_bound(k, self.epsilon, z)), self.min_particles), n)
               for k in range(n + 1)]
        return np.asarray(out, dtype=np.int64)


def _kld_bound(bins: int, epsilon: float, z: float) -> float:
    """:meth:`KLDSampling.bound` for the normal quantile ``z`` of ``1 − δ``."""
    if bins <= 1:
        return 0.0
    d = bins - 1
    a = 2.0 / (9.0 * d)
    return d / (2.0 * epsilon) * (1.0 - a + math.sqrt(a) * z) ** 3


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
