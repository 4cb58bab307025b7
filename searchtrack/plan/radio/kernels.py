"""Numba kernel of the reference scoring: amplitudes and ideal-measurement log-likelihoods of
every particle seen from every child pose (Nguyen et al., eqs. 4 and 22), the step that
:class:`~searchtrack.plan.radio.reference.ReferenceScorer` follows with the update and the
reward (:mod:`~searchtrack.plan.radio.fused` computes all three in fused passes).

It fuses, per pose, label and particle, what :func:`~searchtrack.plan.radio.ideal.amplitudes`
(through :meth:`RadioSignal.amplitude <searchtrack.models.radio.signal.RadioSignal.amplitude>`)
and :meth:`~searchtrack.plan.radio.ideal.IdealLikelihood.log_likelihood` compute in NumPy, the
reference its tests compare it with:

    ``γ = A G_r G_c G_a(φ) (d0² / max(d², d0²))^(κ/4)``, ``G_a = b + (1 − b)(1 + cos φ)/2``,
    ``log g = −n_i γ² E_λ + o_i h_λ(γ̂_λ γ)``,

``h_λ`` read from the same table (cubic Hermite in ``log t``, ``t² q_λ`` below the table).
Serial.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.radio import RadioSignal
from searchtrack.plan.radio.ideal import IdealLikelihood


@njit(cache=True)
def _kernel(xy: FloatArray, poses: FloatArray, gamma_hat: FloatArray, counts: IntArray,
            overlap: IntArray, energy: FloatArray, quadratic: FloatArray, log_t0: float,
            inv_step: float, log_h: FloatArray, slope: FloatArray, scale: float, back: float,
            half_kappa: float, d0: float, height: float, out: FloatArray) -> None:
    n_poses = poses.shape[0]
    n_labels, n = counts.shape
    size = log_h.shape[1]
    low = math.exp(log_t0)
    h2, d02, quarter_kappa = height * height, d0 * d0, half_kappa / 2.0
    step = 1.0 / inv_step
    for c in range(n_poses):
        px, py = poses[c, 0], poses[c, 1]
        ch, sh = math.cos(poses[c, 2]), math.sin(poses[c, 2])
        for lab in range(n_labels):
            gh = gamma_hat[c, lab]
            e = energy[lab]
            for i in range(n):
                dx = xy[lab, i, 0] - px
                dy = xy[lab, i, 1] - py
                g2 = dx * dx + dy * dy
                cos_phi = 1.0
                if g2 > 0.0:
                    cos_phi = min(1.0, max(-1.0, (dx * ch + dy * sh) / math.sqrt(g2)))
                gain = back + (1.0 - back) * (1.0 + cos_phi) / 2.0
                d2 = max(g2 + h2, d02)
                gamma = scale * gain * math.exp(-quarter_kappa * math.log(d2 / d02))
                ll = -counts[lab, i] * e * gamma * gamma
                o = overlap[lab, i]
                if o > 0 and gh > 0.0:
                    t = gh * gamma
                    if t < low:
                        h = quadratic[lab] * t * t
                    else:
                        u = min((math.log(t) - log_t0) * inv_step, size - 1.0)
                        k = min(int(u), size - 2)
                        f = u - k
                        f2 = f * f
                        f3 = f2 * f
                        h = math.exp((2 * f3 - 3 * f2 + 1) * log_h[lab, k]
                                     + (f3 - 2 * f2 + f) * step * slope[lab, k]
                                     + (3 * f2 - 2 * f3) * log_h[lab, k + 1]
                                     + (f3 - f2) * step * slope[lab, k + 1])
                    ll += o * h
                out[c, lab, i] = ll


def ideal_log_likelihoods(signal: RadioSignal, table: IdealLikelihood, xy: FloatArray,
                          poses: FloatArray, gamma_hat: FloatArray, counts: IntArray,
                          overlap: IntArray) -> FloatArray:
    """``(K, Λ, N)`` ``log g`` of particles at ``xy`` ``(Λ, N, 2)`` for the ideal measurements
    of ``K`` poses ``(K, 3)`` with estimate amplitudes ``gamma_hat`` ``(K, Λ)`` (0: no
    estimate) and frame counts and overlaps ``(Λ, N)``."""
    out = np.empty((poses.shape[0], *counts.shape))
    log_t0 = float(table.log_t[0])
    inv_step = (table.log_t.size - 1) / float(table.log_t[-1] - log_t0)
    _kernel(np.ascontiguousarray(xy, dtype=np.float64),
            np.ascontiguousarray(poses, dtype=np.float64),
            np.ascontiguousarray(gamma_hat, dtype=np.float64),
            np.ascontiguousarray(counts, dtype=np.int64),
            np.ascontiguousarray(overlap, dtype=np.int64),
            np.ascontiguousarray(table.energy), np.ascontiguousarray(table.quadratic),
            log_t0, inv_step, np.ascontiguousarray(table.log_h),
            np.ascontiguousarray(table.slope),
            signal.amplitude_v * signal.voltage_gain, signal.back_gain,
            signal.path_loss_exponent / 2.0, signal.reference_distance_m,
            signal.height_difference_m, out)
    return out
