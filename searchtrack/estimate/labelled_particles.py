"""The belief seam for labelled particles: a labelled multi-Bernoulli density, one Bernoulli
particle set per label, all labels in one array.

Nguyen et al.'s JMS TBD-LMB filter (§III-C) keeps, for every known label ``λ`` (a tag
frequency), an existence probability ``r_λ`` and a density over ``(x, s, τ)``: the state
``[px, vx, py, vy]``, the motion mode ``s`` (0 = WD, eq. 46; 1 = CV, eq. 47) and the pulse
offset ``τ``. Under the separable likelihood (Proposition 1) the LMB update (eqs. 28–30) never
couples labels, so the density is a bank of Bernoulli particle sets; here they share
``(Λ, N, ...)`` arrays so every step is vectorised across labels.

:class:`LabelledParticles` is the plain store of such a density (what the radio filters of
:mod:`searchtrack.estimate.radio` carry and what a planner's look-ahead builds); it is a
:class:`~searchtrack.estimate.belief.LabelledParticleBelief`. The pure steps a planner needs to
predict its own copy of any such belief live here too: :func:`update` (eqs. 29–30 in log space)
and :func:`resample` (systematic, per label). The filter's prediction with re-birth
(eqs. 24–27) stays with the filter (:mod:`searchtrack.estimate.radio.particles`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray

if TYPE_CHECKING:
    from searchtrack.estimate.belief import LabelledParticleBelief
    from searchtrack.models.radio import RadioSignal

#: Number of motion modes (0 = WD, 1 = CV).
N_MODES = 2


@dataclass
class LabelledParticles:
    """The particle LMB density: per label ``λ`` a weighted particle set and an existence ``r_λ``.

    Parameters
    ----------
    x
        ``(Λ, N, 4)`` states ``[px, vx, py, vy]`` (m, m/s).
    mode
        ``(Λ, N)`` motion modes (0 = WD, 1 = CV).
    tau
        ``(Λ, N)`` pulse offsets (s) in ``[0, T0)``.
    w
        ``(Λ, N)`` weights, each row normalised to 1.
    r
        ``(Λ,)`` existence probabilities.
    """

    x: FloatArray
    mode: NDArray[np.int8]
    tau: FloatArray
    w: FloatArray
    r: FloatArray

    def __post_init__(self) -> None:
        if self.x.ndim != 3 or self.x.shape[2] != 4:
            raise InvalidInputError("x", self.x.shape, "must have shape (Λ, N, 4)")
        n_labels, n = self.x.shape[:2]
        for name in ("mode", "tau", "w"):
            if getattr(self, name).shape != (n_labels, n):
                raise InvalidInputError(name, getattr(self, name).shape,
                                        f"must have shape ({n_labels}, {n})")
        if self.r.shape != (n_labels,):
            raise InvalidInputError("r", self.r.shape, f"must have shape ({n_labels},)")

    @property
    def n_labels(self) -> int:
        """Number of labels ``Λ``."""
        return int(self.x.shape[0])

    @property
    def n_particles(self) -> int:
        """Particles per label ``N``."""
        return int(self.x.shape[1])

    def copy(self) -> LabelledParticles:
        """A deep copy (writable arrays)."""
        return LabelledParticles(self.x.copy(), self.mode.copy(), self.tau.copy(), self.w.copy(),
                                 self.r.copy())

    def mean_xy(self) -> FloatArray:
        """``(Λ, 2)`` weighted mean ground position ``(px, py)`` of each label (m)."""
        return np.asarray(np.einsum("ln,lnk->lk", self.w, self.x[:, :, ::2]), dtype=np.float64)

    def frame_mode(self, signal: RadioSignal) -> IntArray:
        """``(Λ,)`` weighted mode of the pulse frame ``m(τ)`` (eq. 16) of each label (the
        lowest frame on ties)."""
        frames = np.asarray(signal.frame_of(self.tau), dtype=np.int64)
        low = int(frames.min())
        span = int(frames.max()) - low + 1
        rows = np.arange(self.n_labels)[:, None] * span
        mass = np.bincount((rows + frames - low).ravel(), weights=self.w.ravel(),
                           minlength=self.n_labels * span).reshape(self.n_labels, span)
        return np.asarray(mass.argmax(axis=1) + low, dtype=np.int64)

    def cardinality(self) -> FloatArray:
        """``(Λ + 1,)`` distribution of the number of objects: the Poisson-binomial law of
        ``Σ_λ Bernoulli(r_λ)`` (the LMB cardinality, §II-B)."""
        dist = np.zeros(self.n_labels + 1)
        dist[0] = 1.0
        for r in self.r:
            dist[1:] = dist[1:] * (1.0 - r) + dist[:-1] * r
            dist[0] *= 1.0 - r
        return dist

    def mode_probabilities(self) -> FloatArray:
        """``(Λ, 2)`` posterior probability of each motion mode (WD, CV) per label."""
        return np.stack([(self.w * (self.mode == j)).sum(axis=1) for j in range(N_MODES)],
                        axis=1)


def update(state: LabelledParticleBelief, log_lik: FloatArray) -> LabelledParticles:
    """Eqs. 29–30 with per-particle log-likelihood ratios ``log_lik`` ``(Λ, N)`` (eq. 22).

    ``η_λ = Σ_i w_i g_i`` by log-sum-exp, ``r ← r η / (1 − r + r η)``, ``w_i ← w_i g_i / η``;
    finite for log-likelihoods of any magnitude. The input is unchanged; the result shares its
    ``x``, ``tau`` and (``int8``) ``mode`` arrays.

    Raises
    ------
    InvalidInputError
        When ``log_lik`` is not a finite ``(Λ, N)`` array.
    """
    ll = np.asarray(log_lik, dtype=np.float64)
    if ll.shape != state.w.shape:
        raise InvalidInputError("log_lik", ll.shape, f"must have shape {state.w.shape}")
    if not np.all(np.isfinite(ll)):
        raise InvalidInputError("log_lik", ll.shape, "must be finite")
    with np.errstate(divide="ignore"):
        logw = np.log(state.w) + ll
        peak = logw.max(axis=1, keepdims=True)
        w = np.exp(logw - peak)
        mass = w.sum(axis=1)
        w /= mass[:, None]
        log_eta = peak[:, 0] + np.log(mass)
        a = np.log(state.r) + log_eta
        b = np.log1p(-state.r)
    r = np.exp(a - np.logaddexp(a, b))
    return LabelledParticles(state.x, np.asarray(state.mode, dtype=np.int8), state.tau, w, r)


def resample(state: LabelledParticleBelief, rng: np.random.Generator,
             n: int) -> LabelledParticles:
    """Systematic resampling of every label to ``n`` equally weighted particles (``r`` kept,
    modes as ``int8``): one offset per label drawn from ``rng``, label by label."""
    n = checks.count("n", n, least=1)
    rng = checks.generator("rng", rng)
    w = np.asarray(state.w, dtype=np.float64)
    n_labels = int(w.shape[0])
    idx = _systematic(w, rng.random(n_labels), n)
    x, tau = np.empty((n_labels, n, 4)), np.empty((n_labels, n))
    mode = np.empty((n_labels, n), dtype=np.int8)
    _gather(np.asarray(state.x, dtype=np.float64), np.asarray(state.mode, dtype=np.int8),
            np.asarray(state.tau, dtype=np.float64), idx, x, mode, tau)
    return LabelledParticles(x, mode, tau, np.full((n_labels, n), 1.0 / n),
                             np.array(state.r, copy=True))


@njit(cache=True)
def _gather(x: FloatArray, mode: NDArray[np.integer[Any]], tau: FloatArray, idx: IntArray,
            out_x: FloatArray, out_mode: NDArray[np.integer[Any]], out_tau: FloatArray) -> None:
    """``out_*[b, j] = *[b, idx[b, j]]``: row-wise copies of the chosen particles."""
    for b in range(idx.shape[0]):
        for j in range(idx.shape[1]):
            k = idx[b, j]
            for c in range(4):
                out_x[b, j, c] = x[b, k, c]
            out_mode[b, j] = mode[b, k]
            out_tau[b, j] = tau[b, k]


@njit(cache=True)
def _systematic(w: FloatArray, u: FloatArray, n: int) -> IntArray:
    """``(B, n)`` systematic resampling indices of each row of weights ``w`` ``(B, m)``: row
    ``b`` takes, for ``j = 0..n−1``, the first particle whose cumulative weight exceeds
    ``(u_b + j) / n`` of the row's total, for offsets ``u`` ``(B,)`` in ``[0, 1)``."""
    rows, m = w.shape
    idx = np.empty((rows, n), dtype=np.int64)
    for b in range(rows):
        total = 0.0
        for i in range(m):
            total += w[b, i]
        k = 0
        cum = w[b, 0]
        for j in range(n):
            target = (u[b] + j) / n * total
            while cum <= target and k < m - 1:
                k += 1
                cum += w[b, k]
            idx[b, j] = k
    return idx
