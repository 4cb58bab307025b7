"""Measurement-driven proposals for the pulse offset τ of birth particles.

The birth density of every label draws τ uniformly on ``[0, T0)`` (§III-C; the paper does not
give it). Only the frame index ``m(τ) = ⌈τ f_s / R⌉`` (eq. 16) reaches the likelihood, so τ lives
on ``C`` cells: cell ``c`` holds the offsets whose pulse fills frames ``c`` and ``c + 1``, the
interval ``((c − 1) R / f_s, c R / f_s] ∩ [0, T0)``, of birth mass ``p_B(c)`` = its length over
T0. With a few thousand particles per label a uniform draw leaves most cells empty, so a weak
tag's cell is rarely tried and its evidence is not integrated.

A proposal ``q(c)`` puts birth particles where the current measurement points, and the birth
particles are reweighted by ``p_B(c) / q(c)`` (importance sampling), so the predicted density —
and the filter — stay those of the paper; only the Monte Carlo error changes. Every proposal
here is the mixture ``q = ε p_B + (1 − ε) q_data`` (``ε`` = ``uniform_share``), so it covers
every cell ``p_B`` does and the weights stay bounded by ``1/ε``.

- :func:`energy_proposal` (TBD, raw cells): ``q_data(c) ∝ exp(S_c)`` with ``S_c`` the
  leakage-weighted energy of the label's bins in frames ``c`` and ``c + 1`` above its noise mean.
- :func:`detection_proposal` (DTT): ``q_data`` uniform over the cells whose frames hold a peak of
  the label (none: ``q = p_B``).
"""

from __future__ import annotations

import math

import numpy as np

from searchtrack.core import checks
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.radio.signal import RadioSignal


def frame_cells(signal: RadioSignal) -> tuple[FloatArray, FloatArray]:
    """``(low, width)`` of the ``C`` τ cells, cell ``c`` = ``(low_c, low_c + width_c]``; cell 0
    is the single point ``τ = 0`` (width 0)."""
    hop_s = signal.hop / signal.sample_rate_hz
    n_cells = math.ceil(signal.period_s / hop_s - 1e-12) + 1
    c = np.arange(n_cells, dtype=np.float64)
    low = np.maximum(0.0, (c - 1.0) * hop_s)
    high = np.minimum(signal.period_s, c * hop_s)
    return low, np.maximum(0.0, high - low)


def birth_cell_mass(signal: RadioSignal) -> FloatArray:
    """``(C,)`` ``p_B(c)``: the uniform birth density's mass on each cell (sums to 1)."""
    _, width = frame_cells(signal)
    return np.asarray(width / width.sum(), dtype=np.float64)


def _mix(signal: RadioSignal, data: FloatArray, uniform_share: float) -> FloatArray:
    share = checks.real("uniform_share", uniform_share, low=0.0, high=1.0, low_open=True)
    p_b = birth_cell_mass(signal)
    data = data * (p_b > 0.0)
    total = data.sum(axis=1, keepdims=True)
    q = np.where(total > 0.0, data / np.where(total > 0.0, total, 1.0), p_b)
    return np.asarray(share * p_b + (1.0 - share) * q, dtype=np.float64)


def energy_proposal(signal: RadioSignal, z: FloatArray, *,
                    uniform_share: float = 0.5) -> FloatArray:
    """``(Λ, C)`` proposal from the raw magnitudes ``z`` ``(M, L)``: ``S_c = s_c + s_{c+1}`` with
    ``s_m = Σ_b |W_b|² z_{m,b}² / (2 Σ_z Σ_b |W_b|²) − 1`` over the label's bins (zero mean on
    noise alone; frames outside ``[0, M)`` count 0), and ``q_data ∝ exp(S_c − max S)``."""
    bins, leak = signal.tag_bins(), signal.tag_leakage()
    weight = leak**2 / (leak**2).sum(axis=1, keepdims=True)
    s = np.einsum("lb,mlb->lm", weight, z[:, bins] ** 2) / (2.0 * signal.cell_var) - 1.0
    low, _ = frame_cells(signal)
    n_cells = low.size
    padded = np.zeros((signal.n_labels, n_cells + 1))
    m = min(signal.frames, n_cells + 1)
    padded[:, :m] = s[:, :m]
    score = padded[:, :n_cells] + padded[:, 1:n_cells + 1]
    data = np.exp(score - score.max(axis=1, keepdims=True))
    return _mix(signal, data, uniform_share)


def detection_proposal(signal: RadioSignal, frame: IntArray, bin_: IntArray, *,
                       uniform_share: float = 0.5) -> FloatArray:
    """``(Λ, C)`` proposal from peaks at ``(frame, bin_)``: uniform over the cells ``m − 1`` and
    ``m`` of each peak of the label (a peak in its bins), ``p_B`` for a label without peaks."""
    bins = signal.tag_bins()
    n_cells = frame_cells(signal)[0].size
    data = np.zeros((signal.n_labels, n_cells))
    for lab in range(signal.n_labels):
        mine = np.isin(bin_, bins[lab])
        for f in np.asarray(frame)[mine]:
            for c in (int(f) - 1, int(f)):
                if 0 <= c < n_cells:
                    data[lab, c] = 1.0
    return _mix(signal, data, uniform_share)


def draw_tau(signal: RadioSignal, proposal: FloatArray, n: int,
             rng: np.random.Generator) -> tuple[FloatArray, FloatArray]:
    """``n`` offsets per label from ``proposal`` ``(Λ, C)`` and their importance ratios
    ``p_B(c) / q(c)``: ``(tau (Λ, n), ratio (Λ, n))``; within its cell τ is uniform."""
    low, width = frame_cells(signal)
    p_b = birth_cell_mass(signal)
    q = checks.finite_array("proposal", proposal, (signal.n_labels, low.size))
    cdf = np.cumsum(q, axis=1)
    cdf /= cdf[:, -1:]
    u = rng.random((signal.n_labels, n))
    cell = np.minimum(np.array([np.searchsorted(cdf[i], u[i], side="right")
                                for i in range(signal.n_labels)]), low.size - 1)
    tau = low[cell] + (1.0 - rng.random((signal.n_labels, n))) * width[cell]
    ratio = p_b[cell] / np.take_along_axis(q, cell, axis=1)
    return np.asarray(tau, dtype=np.float64), np.asarray(ratio, dtype=np.float64)
