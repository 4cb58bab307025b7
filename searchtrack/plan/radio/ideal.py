"""The likelihood of the predicted ideal measurement (PIMS), tabulated (Nguyen et al., eq. 22).

The ideal measurement ``ẑ`` seen from a pose is noise-free: ``γ̂_λ |W_b|`` on the cells
``{m̂, m̂+1} ∩ [0, M) × S(λ)`` of each estimated label (amplitude ``γ̂_λ`` of the estimate at
that pose, eq. 4), and 0 on every other cell of the influence regions — including all cells of a
label that has no estimate (``r ≤ 0.5``): evidence of absence. A particle of label λ with
amplitude ``γ_i`` and frames ``{m_i, m_i+1} ∩ [0, M)`` (``n_i`` of them, ``o_i`` shared with the
estimate's) then has the log-likelihood ratio of eq. 22

    ``log g_i = −n_i γ_i² Σ_b W_b² / (2 Σ_z) + o_i h_λ(γ̂_λ γ_i)``,
    ``h_λ(t) = Σ_b log I0(t W_b² / Σ_z)``,

because ``log I0(0) = 0``. :class:`IdealLikelihood` tabulates ``log h_λ`` and its slope
``d log h_λ / d log t = t Σ_b c_b I1(c_b t)/I0(c_b t) / h_λ`` (``c_b = W_b²/Σ_z``) once per
solve on a uniform grid of ``log t`` up to the largest possible ``t``, the squared amplitude of a
tag straight below the UAV, and interpolates by cubic Hermite polynomials (relative error below
1e-10); below the grid, where every argument of ``log I0`` is under 1e-3,
``h_λ(t) ≈ t² Σ_b c_b² / 4`` (relative error below 1e-7).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.special import i0e, i1e

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.radio import RadioSignal

#: Nodes of the table of ``h_λ``.
TABLE_SIZE = 2048

#: The table starts where the largest ``log I0`` argument is this small.
SMALL_ARGUMENT = 1e-3


def log_i0(x: FloatArray) -> FloatArray:
    """``log I0(x)`` for ``x ≥ 0`` (via SciPy's scaled ``i0e``, no overflow)."""
    return np.asarray(np.log(i0e(x)) + x, dtype=np.float64)


def frame_counts(frames: IntArray, n_frames: int) -> IntArray:
    """``n_i``: how many of the frames ``{m_i, m_i + 1}`` lie in ``[0, M)``."""
    m = np.asarray(frames)
    return np.asarray(((m >= 0) & (m < n_frames)).astype(np.int64)
                      + ((m + 1 >= 0) & (m + 1 < n_frames)), dtype=np.int64)


def frame_overlap(frames: IntArray, estimate: IntArray, n_frames: int) -> IntArray:
    """``o_i``: frames of ``{m_i, m_i+1} ∩ [0, M)`` that are also estimate frames
    ``{m̂, m̂+1}``; ``frames`` ``(..., Λ, N)``, ``estimate`` ``(..., Λ)``."""
    m = np.asarray(frames)
    e = np.asarray(estimate)[..., None]
    out = np.zeros(m.shape, dtype=np.int64)
    for a in (m, m + 1):
        out += (a >= 0) & (a < n_frames) & ((a == e) | (a == e + 1))
    return out


def amplitudes(signal: RadioSignal, xy: FloatArray, poses: FloatArray) -> FloatArray:
    """``(K, ...)`` amplitudes ``γ`` (eq. 4) of tags at ``xy`` ``(..., 2)`` seen from each of
    ``K`` poses ``(K, 3)``: the tags are moved into each pose's frame (the amplitude depends only
    on the relative position and the bearing) and evaluated from the origin, heading 0."""
    p = np.asarray(poses, dtype=np.float64)
    pts = np.asarray(xy, dtype=np.float64)
    extra = (None,) * (pts.ndim - 1)
    dx = pts[None, ..., 0] - p[(slice(None), *extra, 0)]
    dy = pts[None, ..., 1] - p[(slice(None), *extra, 1)]
    c = np.cos(p[(slice(None), *extra, 2)])
    s = np.sin(p[(slice(None), *extra, 2)])
    rel = np.stack([c * dx + s * dy, c * dy - s * dx], axis=-1)
    return signal.amplitude(rel, np.zeros(3))


@dataclass(frozen=True, eq=False)
class IdealLikelihood:
    """``log g`` of the ideal measurement for batches of particles and poses (module
    docstring). Build with :meth:`of`.

    Parameters
    ----------
    signal
        The signal model.
    energy
        ``(Λ,)`` ``Σ_b W_b² / (2 Σ_z)``.
    quadratic
        ``(Λ,)`` ``Σ_b c_b² / 4``, the small-``t`` coefficient of ``h_λ``.
    log_t
        ``(G,)`` table nodes ``log t``.
    log_h
        ``(Λ, G)`` ``log h_λ`` at the nodes.
    slope
        ``(Λ, G)`` ``d log h_λ / d log t`` at the nodes.
    """

    signal: RadioSignal
    energy: FloatArray
    quadratic: FloatArray
    log_t: FloatArray
    log_h: FloatArray
    slope: FloatArray

    @classmethod
    def of(cls, signal: RadioSignal, size: int = TABLE_SIZE) -> IdealLikelihood:
        """The table for ``signal``: ``t`` from where the largest ``c_b t`` is
        :data:`SMALL_ARGUMENT` to the square of the largest amplitude."""
        c = signal.tag_leakage() ** 2 / signal.cell_var                     # (Λ, B)
        top = float(signal.amplitude(np.zeros(2), np.zeros(3))) ** 2 * (1.0 + 1e-9)
        low = min(SMALL_ARGUMENT / float(c.max()), 0.5 * top)
        log_t = np.linspace(math.log(low), math.log(top), size)
        x = np.exp(log_t)[None, :, None] * c[:, None, :]                  # (Λ, G, B)
        h = log_i0(x).sum(axis=2)
        slope = (x * i1e(x) / i0e(x)).sum(axis=2) / h
        energy = 0.5 * np.sum(signal.tag_leakage() ** 2, axis=1) / signal.cell_var
        return cls(signal, energy, 0.25 * np.sum(c**2, axis=1), log_t, np.log(h), slope)

    def h(self, label: int, t: FloatArray) -> FloatArray:
        """``h_λ(t)`` for ``t ≥ 0`` of any shape (tabulated; clamped above the table)."""
        tt = np.asarray(t, dtype=np.float64)
        log_t0 = float(self.log_t[0])
        low = math.exp(log_t0)
        inv_step = (self.log_t.size - 1) / float(self.log_t[-1] - log_t0)
        table, slope = self.log_h[label], self.slope[label]
        u = np.clip((np.log(np.maximum(tt, low)) - log_t0) * inv_step, 0.0, table.size - 1.0)
        i = np.minimum(u.astype(np.int64), table.size - 2)
        f = u - i
        f2, f3 = f * f, f * f * f
        step = 1.0 / inv_step
        inside = np.exp((2 * f3 - 3 * f2 + 1) * table[i] + (f3 - 2 * f2 + f) * step * slope[i]
                        + (3 * f2 - 2 * f3) * table[i + 1] + (f3 - f2) * step * slope[i + 1])
        return np.asarray(np.where(tt < low, self.quadratic[label] * tt * tt, inside),
                          dtype=np.float64)

    def h_exact(self, label: int, t: FloatArray) -> FloatArray:
        """``h_λ(t)`` computed directly (the reference of :meth:`h`)."""
        c = self.signal.tag_leakage()[label] ** 2 / self.signal.cell_var
        return np.asarray(log_i0(np.multiply.outer(np.asarray(t, dtype=np.float64), c))
                          .sum(axis=-1), dtype=np.float64)

    def log_likelihood(self, gamma: FloatArray, counts: IntArray, overlap: IntArray,
                       gamma_hat: FloatArray) -> FloatArray:
        """``(K, Λ, N)`` ``log g_i`` of the ideal measurements of ``K`` poses.

        Parameters
        ----------
        gamma
            ``(K, Λ, N)`` particle amplitudes at each pose.
        counts
            ``(Λ, N)`` ``n_i`` (:func:`frame_counts`).
        overlap
            ``(Λ, N)`` ``o_i`` (:func:`frame_overlap`).
        gamma_hat
            ``(K, Λ)`` estimate amplitudes at each pose, 0 for labels without an estimate.
        """
        out = -(counts * self.energy[:, None]) * gamma * gamma
        for lab in range(gamma.shape[1]):
            if not np.any(gamma_hat[:, lab] > 0.0):
                continue
            t = gamma_hat[:, lab, None] * gamma[:, lab, :]
            out[:, lab, :] += overlap[lab] * self.h(lab, t)
        return np.asarray(out, dtype=np.float64)


@lru_cache(maxsize=16)
def likelihood_table(signal: RadioSignal) -> IdealLikelihood:
    """:meth:`IdealLikelihood.of` ``signal`` (default size), tabulated once per signal and
    shared (its arrays read-only)."""
    table = IdealLikelihood.of(signal)
    for arr in (table.energy, table.quadratic, table.log_t, table.log_h, table.slope):
        arr.setflags(write=False)
    return table
