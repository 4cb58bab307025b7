"""The update and reward of a batch of children in fused passes (Nguyen et al., eqs. 4, 22,
29–30, 33, 41–43).

For every child ``c`` (end pose of its interval, parent ``p(c)``), label ``λ`` and particle ``i``
of the look-ahead cloud at the interval's end:

* amplitude (eq. 4): ``log γ = log(A G_r G_c) + log G_a(φ) − (κ/4) log(max(d², d0²)/d0²)``;
* ideal-measurement log-likelihood (eq. 22): ``log g = −n_i γ² E_λ + o_i h_λ(γ̂_λ γ)``, ``h_λ``
  read from the table of :class:`~searchtrack.plan.radio.ideal.IdealLikelihood` (cubic Hermite
  in ``log t``, ``q_λ t²`` below it);
* update (eqs. 29–30) of the parent's log weights: ``u_i = log w_i + log g_i − max``,
  ``η = e^max Σ_i e^{u_i}``, ``log w'_i = u_i − log Σ e^u``, ``r' = r η / (1 − r + r η)``;
* reward ``D(π₂, π₁)`` from per-label particle sums: ``Σ_i ω₂^α ω₁^{1−α}`` (Rényi, eq. 41),
  ``Σ_i ω₂ log(ω₂/ω₁)`` (α = 1), or ``Σ ω₂ω₁`` and ``Σ ω₂²`` (Cauchy–Schwarz, eq. 43),
  combined per label by :func:`~searchtrack.plan.radio.divergences.renyi_label_terms` and
  :func:`~searchtrack.plan.radio.divergences.cauchy_schwarz_of_sums`.

The arithmetic runs in Numba passes over ``(children, Λ, N)`` blocks of bounded size, the
logarithms and exponentials in between as NumPy's vectorised ufuncs on whole blocks; a child's
parent is read by index, so a prefix's posterior is shared by all its children without copies.
The maxima and sums over particles may be accumulated in vector lanes (reassociated): equal to
the sequential ones up to rounding, and the same on every run.
:class:`~searchtrack.plan.radio.reference.ReferenceScorer` is the step-by-step reference.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit

from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.radio import RadioSignal
from searchtrack.plan.radio.divergences import cauchy_schwarz_of_sums, renyi_label_terms
from searchtrack.plan.radio.ideal import IdealLikelihood

#: Particle entries ``children · Λ · N`` per block of the fused passes.
BLOCK_ELEMENTS = 1 << 15


@njit(cache=True, error_model="numpy")
def _geometry(x: FloatArray, y: FloatArray, poses: FloatArray, back: float, height: float,
              d0: float, q: FloatArray, gain: FloatArray) -> None:
    """``q = max(d², d0²)/d0²`` and the antenna gain ``G_a(φ)`` of every particle at ``x``, ``y``
    ``(Λ, N)`` from every pose, into ``q`` and ``gain`` ``(C, Λ, N)``."""
    n_labels, n = x.shape
    h2, d02 = height * height, d0 * d0
    for c in range(poses.shape[0]):
        px, py = poses[c, 0], poses[c, 1]
        ch, sh = math.cos(poses[c, 2]), math.sin(poses[c, 2])
        for lab in range(n_labels):
            xr, yr, qr, gr = x[lab], y[lab], q[c, lab], gain[c, lab]
            for i in range(n):
                dx = xr[i] - px
                dy = yr[i] - py
                g2 = dx * dx + dy * dy
                ratio = (dx * ch + dy * sh) / math.sqrt(g2)
                cos_phi = min(1.0, max(-1.0, ratio)) if g2 > 0.0 else 1.0
                gr[i] = back + (1.0 - back) * (1.0 + cos_phi) / 2.0
                qr[i] = max(g2 + h2, d02) / d02


@njit(cache=True, error_model="numpy")
def _exponents(lq: FloatArray, lgain: FloatArray, log_gamma_hat: FloatArray,
               overlap: IntArray, log_scale: float, quarter_kappa: float, log_t0: float,
               inv_step: float, coef: FloatArray, log_quadratic: FloatArray) -> None:
    """From ``log q`` and ``log G_a`` (in ``lq``, ``lgain``): ``2 log γ`` into ``lq`` and
    ``log h_λ(γ̂ γ)`` (``−inf`` where the term is absent) into ``lgain``; ``coef`` ``(Λ, G−1,
    4)`` the cubic of each table interval (:func:`hermite_coefficients`)."""
    n_children, n_labels, n = lq.shape
    size = coef.shape[1] + 1
    top = size - 1.0
    for c in range(n_children):
        for lab in range(n_labels):
            lgh = log_gamma_hat[c, lab]
            qr, gr, orow = lq[c, lab], lgain[c, lab], overlap[lab]
            for i in range(n):
                qr[i] = 2.0 * (log_scale + gr[i] - quarter_kappa * qr[i])
            if lgh == -math.inf:
                gr[:] = -math.inf
                continue
            cf, quad = coef[lab], log_quadratic[lab]
            for i in range(n):
                lt = lgh + 0.5 * qr[i]
                u = min((lt - log_t0) * inv_step, top)
                k = min(int(max(u, 0.0)), size - 2)
                f = u - k
                e = cf[k, 0] + f * (cf[k, 1] + f * (cf[k, 2] + f * cf[k, 3]))
                e = quad + 2.0 * lt if lt < log_t0 else e
                gr[i] = e if orow[i] > 0 else -math.inf


@lru_cache(maxsize=16)
def hermite_coefficients(table: IdealLikelihood) -> FloatArray:
    """``(Λ, G−1, 4)`` the cubic Hermite interpolant of ``log h_λ`` on each interval of the
    table in powers of the interval's fraction ``f``: ``a0 + f(a1 + f(a2 + f a3))`` with
    ``a0 = y_k``, ``a1 = δ s_k``, ``a2 = 3(y_{k+1} − y_k) − δ(2 s_k + s_{k+1})``,
    ``a3 = 2(y_k − y_{k+1}) + δ(s_k + s_{k+1})`` (``y = log h``, ``s`` its slope, ``δ`` the
    step in ``log t``): the Hermite basis form of :meth:`IdealLikelihood.h
    <searchtrack.plan.radio.ideal.IdealLikelihood.h>` regrouped."""
    log_t0 = float(table.log_t[0])
    step = 1.0 / ((table.log_t.size - 1) / float(table.log_t[-1] - log_t0))
    y0, y1 = table.log_h[:, :-1], table.log_h[:, 1:]
    s0, s1 = step * table.slope[:, :-1], step * table.slope[:, 1:]
    coef = np.ascontiguousarray(np.stack(
        [y0, s0, 3.0 * (y1 - y0) - 2.0 * s0 - s1, 2.0 * (y0 - y1) + s0 + s1], axis=2))
    coef.setflags(write=False)
    return coef


@njit(cache=True, error_model="numpy", fastmath={"reassoc", "nsz"})
def _posterior(gamma2: FloatArray, h: FloatArray, counts: IntArray, overlap: IntArray,
               energy: FloatArray, log_w: FloatArray, parent: IntArray, log_w1: FloatArray,
               alpha: float, post: FloatArray, peak: FloatArray) -> None:
    """``u = log w_p(c) + log g − max`` into ``post``, the max into ``peak`` ``(C, Λ)``, and
    ``α u + (1 − α) log ω₁`` into ``gamma2`` (read first)."""
    n_children, n_labels, n = gamma2.shape
    for c in range(n_children):
        b = parent[c]
        for lab in range(n_labels):
            e = energy[lab]
            gr, hr, pr, wr = gamma2[c, lab], h[c, lab], post[c, lab], log_w[b, lab]
            nr, orow, w1r = counts[lab], overlap[lab], log_w1[lab]
            top = -math.inf
            for i in range(n):
                ll = -nr[i] * e * gr[i]
                o = orow[i]
                ll = ll + o * hr[i] if o > 0 else ll
                v = wr[i] + ll
                pr[i] = v
                top = max(top, v)
            peak[c, lab] = top
            for i in range(n):
                v = pr[i] - top
                pr[i] = v
                gr[i] = alpha * v + (1.0 - alpha) * w1r[i]


@njit(cache=True, error_model="numpy", fastmath={"reassoc", "nsz"})
def _sums(post: FloatArray, expo: FloatArray, powered: FloatArray, log_w1: FloatArray,
          w1: FloatArray, kind: int, keep: bool, log_w: FloatArray, mass: FloatArray,
          inner: FloatArray, own: FloatArray) -> None:
    """Per child and label: ``Σ e^u`` into ``mass``, the reward's particle sums into ``inner``
    and ``own`` (``kind`` 0: Rényi, 1: Kullback–Leibler, 2: Cauchy–Schwarz) and, when ``keep``,
    the posterior log weights into ``log_w``."""
    n_children, n_labels, n = post.shape
    for c in range(n_children):
        for lab in range(n_labels):
            pr, er, w1r, lw1r = post[c, lab], expo[c, lab], w1[lab], log_w1[lab]
            s = 0.0
            for i in range(n):
                s += er[i]
            log_s = math.log(s)
            mass[c, lab] = s
            if keep:
                out = log_w[c, lab]
                for i in range(n):
                    out[i] = pr[i] - log_s
            a = 0.0
            b = 0.0
            if kind == 0:
                pw = powered[c, lab]
                for i in range(n):
                    a += pw[i]
            elif kind == 1:
                for i in range(n):
                    q2 = er[i] / s
                    a += q2 * (pr[i] - log_s - lw1r[i]) if q2 > 0.0 else 0.0
            else:
                for i in range(n):
                    q2 = er[i] / s
                    a += q2 * w1r[i]
                    b += q2 * q2
            inner[c, lab] = a
            own[c, lab] = b


@dataclass(frozen=True)
class ChildScores:
    """The update and reward of ``C`` children: ``log_w`` ``(C, Λ, N)`` (``(C, Λ, 0)`` when
    not kept), ``r`` ``(C, Λ)``, ``reward`` ``(C,)``."""

    log_w: FloatArray
    r: FloatArray
    reward: FloatArray


def score_children(signal: RadioSignal, table: IdealLikelihood, xy: FloatArray,
                   poses: FloatArray, gamma_hat: FloatArray, counts: IntArray,
                   overlap: IntArray, log_w: FloatArray, r: FloatArray, parent: IntArray,
                   r1: FloatArray, w1: FloatArray, reward: str, order: float, *,
                   keep: bool = True) -> ChildScores:
    """Update the parents ``log_w`` ``(P, Λ, N)``, ``r`` ``(P, Λ)`` of ``C`` children
    (``parent`` ``(C,)``) by the ideal measurement at their end ``poses`` ``(C, 3)`` of the
    cloud ``xy`` ``(Λ, N, 2)`` and score ``D(π₂, π₁)`` against ``r1``, ``w1`` (module
    docstring). ``reward``: ``"renyi"`` (``order`` α) or ``"cs"`` (``order`` K);
    ``keep=False`` skips the posterior weights (a leaf's)."""
    n_children = poses.shape[0]
    n_labels, n = counts.shape
    kind = 2 if reward == "cs" else (1 if order == 1.0 else 0)
    alpha = order if kind == 0 else 1.0
    with np.errstate(divide="ignore"):
        log_w1 = np.log(w1)
        log_gamma_hat = np.log(gamma_hat)
        log_quadratic = np.log(table.quadratic)
    log_t0 = float(table.log_t[0])
    inv_step = (table.log_t.size - 1) / float(table.log_t[-1] - log_t0)
    coef = hermite_coefficients(table)
    out_w = np.empty((n_children, n_labels, n if keep else 0))
    mass, inner, own = (np.empty((n_children, n_labels)) for _ in range(3))
    peak = np.empty((n_children, n_labels))
    step = max(1, BLOCK_ELEMENTS // max(1, n_labels * n))
    size = min(step, n_children)
    first, second, third, fourth = (np.empty((size, n_labels, n)) for _ in range(4))
    x = np.ascontiguousarray(xy[..., 0], dtype=np.float64)
    y = np.ascontiguousarray(xy[..., 1], dtype=np.float64)
    log_scale = math.log(signal.amplitude_v * signal.voltage_gain)
    for lo in range(0, n_children, step):
        hi = min(n_children, lo + step)
        q, g, post, expo = (a[:hi - lo] for a in (first, second, third, fourth))
        _geometry(x, y, poses[lo:hi], signal.back_gain, signal.height_difference_m,
                  signal.reference_distance_m, q, g)
        np.log(q, out=q)
        np.log(g, out=g)
        _exponents(q, g, log_gamma_hat[lo:hi], overlap, log_scale,
                   signal.path_loss_exponent / 4.0, log_t0, inv_step, coef, log_quadratic)
        np.exp(q, out=q)
        np.exp(g, out=g)
        _posterior(q, g, counts, overlap, table.energy, log_w, parent[lo:hi], log_w1, alpha,
                   post, peak[lo:hi])
        np.exp(post, out=expo)
        if kind == 0:
            np.exp(q, out=q)
        _sums(post, expo, q, log_w1, w1, kind, keep, out_w[lo:hi], mass[lo:hi], inner[lo:hi],
              own[lo:hi])
    r_parent = r[parent]
    with np.errstate(divide="ignore"):
        log_eta = peak + np.log(mass)
        a = np.log(r_parent) + log_eta
        b = np.log1p(-r_parent)
        r2 = np.where(r_parent > 0.0, np.exp(a - np.logaddexp(a, b)), 0.0)
    if kind == 2:
        value = cauchy_schwarz_of_sums(r1, r2, inner, own, np.sum(w1 * w1, axis=-1), order)
    else:
        if kind == 0:
            inner = inner * np.exp(-alpha * np.log(mass))
        value = np.asarray(np.sum(renyi_label_terms(r1, r2, inner, alpha), axis=-1),
                           dtype=np.float64)
    return ChildScores(out_w, r2, value)
