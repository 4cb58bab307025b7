"""The separable track-before-detect likelihood of Nguyen et al. (Proposition 1, eq. 22).

A tag of label ``λ`` with amplitude ``γ`` and pulse frame ``m = m(τ)`` (eq. 16) lights the cells
``{m, m + 1} × S(λ)`` of the STFT magnitude ``z`` (``M × L``, eq. 11); a cell's Rice-over-Rayleigh
log-likelihood ratio (eqs. 54–55, Lemma 2) is::

    log φ(z; ν, Σ_z) − log ϕ(z; Σ_z) = −ν² / (2 Σ_z) + log I0(z ν / Σ_z),   ν = γ |W(b − f_λ L/f_s)|

with ``Σ_z = E_w Σ_η / 2`` (:attr:`RadioSignal.cell_var`), the leakage ``|W|`` of
:meth:`RadioSignal.tag_leakage` on the bins of :meth:`RadioSignal.tag_bins`. ``log g_z(x)`` is the
sum over the influence region; frames outside ``[0, M)`` contribute nothing (a pulse at the end
of the interval lights one frame only).

:func:`log_likelihood_ratio` is a serial Numba kernel: ``log I0`` by the Abramowitz–Stegun
polynomials 9.8.1 (``x < 3.75``) and 9.8.2 (``x ≥ 3.75``, ``I0(x) = e^x x^{−1/2} P(3.75/x)``),
absolute error below 1e-6 per cell, the factors multiplied and one logarithm taken per particle.
:func:`log_likelihood_ratio_reference` is the NumPy form with ``log I0(x) = log i0e(x) + x``
(SciPy), kept for the tests. :func:`label_log_likelihoods` evaluates every label's particles at
once from their states and the UAV pose in one Numba pass that also computes each particle's
``γ`` (:meth:`RadioSignal.amplitude`'s formula, :func:`amplitude`; equal up to a few ulp) and
frame ``m(τ)`` (:meth:`RadioSignal.frame_of`, exactly).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import ArrayLike
from scipy.special import i0e

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.radio import RadioSignal

# Abramowitz & Stegun 9.8.1 (t = x / 3.75, |x| ≤ 3.75) and 9.8.2 (u = 3.75 / x, x ≥ 3.75).
_A1, _A2, _A3 = 3.5156229, 3.0899424, 1.2067492
_A4, _A5, _A6 = 0.2659732, 0.0360768, 0.0045813
_B0, _B1, _B2 = 0.39894228, 0.01328592, 0.00225319
_B3, _B4, _B5 = -0.00157565, 0.00916281, -0.02057706
_B6, _B7, _B8 = 0.02635537, -0.01647633, 0.00392377
#: Take the logarithm of the running product before it leaves this range.
_FLUSH_LOW, _FLUSH_HIGH = 1e-200, 1e200


@njit(cache=True)
def _label_cells(z: FloatArray, bins: IntArray, lab: int) -> FloatArray:
    """``(M, B)`` magnitudes ``|z|`` on the bins ``S(λ)`` of label ``lab``, frame by frame."""
    cells = np.empty((z.shape[0], bins.shape[1]))
    for m in range(z.shape[0]):
        for b in range(bins.shape[1]):
            cells[m, b] = abs(z[m, bins[lab, b]])
    return cells


@njit(cache=True)
def _half_energy(leak: FloatArray, inv_var: float) -> float:
    """``Σ_b |W_b|² / (2 Σ_z)`` of one label: ``Σ_b ν_b²/(2Σ_z)`` is ``γ²`` times this."""
    energy = 0.0
    for b in range(leak.shape[0]):
        energy += leak[b] * leak[b]
    return 0.5 * energy * inv_var


@njit(cache=True, inline="always")
def _particle_llr(cells: FloatArray, leak: FloatArray, g: float, first: int, inv_var: float,
                  half: float) -> float:
    """Eq. 22 of one particle with amplitude ``g`` and pulse frame ``first`` on its label's
    ``cells`` ``(M, B)`` and leakage ``leak`` ``(B,)``; ``half`` from :func:`_half_energy`."""
    total = 0.0
    prod = 1.0
    for m in range(max(first, 0), min(first + 2, cells.shape[0])):
        total -= g * g * half
        for b in range(cells.shape[1]):
            x = cells[m, b] * abs(g * leak[b] * inv_var)      # x = z ν / Σ_z
            if x < 3.75:
                t = x * (1.0 / 3.75)
                t = t * t
                prod *= 1.0 + t * (_A1 + t * (_A2 + t * (_A3 + t * (
                    _A4 + t * (_A5 + t * _A6)))))
            else:
                rs = 1.0 / math.sqrt(x)
                u = 3.75 * rs * rs
                total += x
                prod *= (_B0 + u * (_B1 + u * (_B2 + u * (_B3 + u * (_B4 + u * (
                    _B5 + u * (_B6 + u * (_B7 + u * _B8)))))))) * rs
            if prod < _FLUSH_LOW or prod > _FLUSH_HIGH:
                total += math.log(prod)
                prod = 1.0
    return total + math.log(prod)


@njit(cache=True)
def _llr_kernel(z: FloatArray, bins: IntArray, leak: FloatArray, gamma: FloatArray,
                frame: IntArray, inv_var: float, out: FloatArray) -> None:
    """Eq. 22 into ``out`` ``(Λ, N)`` for amplitudes ``gamma`` and frames ``frame`` ``(Λ, N)``
    of each label's particles, with bins ``bins`` and leakage ``leak`` ``(Λ, B)`` per label."""
    for lab in range(gamma.shape[0]):
        cells = _label_cells(z, bins, lab)
        half = _half_energy(leak[lab], inv_var)
        for i in range(gamma.shape[1]):
            out[lab, i] = _particle_llr(cells, leak[lab], gamma[lab, i], frame[lab, i], inv_var,
                                        half)


@njit(cache=True, inline="always")
def _amplitude(px: float, py: float, geo: FloatArray) -> float:
    """``γ = A G_r G_c G_a(φ) (d0/d)^(κ/2)`` of a tag at ``(px, py)`` as
    :meth:`RadioSignal.amplitude` (``d = max(√(ρ² + h²), d0)``, ``ρ`` the ground range,
    ``cos φ = 1`` straight below), with ``(d0/d)^(κ/2) = exp(−(κ/4) log(d²/d0²))`` (faster
    here than ``pow``; equal up to a few ulp);
    ``geo = [x_u, y_u, cos θ_u, sin θ_u, h, d0, κ/2, A G_r G_c, b]``."""
    dx, dy = px - geo[0], py - geo[1]
    ground2 = dx * dx + dy * dy
    ground = math.sqrt(ground2)
    cos_phi = (dx * geo[2] + dy * geo[3]) / ground if ground > 0.0 else 1.0
    cos_phi = min(max(cos_phi, -1.0), 1.0)
    gain = geo[8] + (1.0 - geo[8]) * (1.0 + cos_phi) / 2.0
    ref2 = geo[5] * geo[5]
    dist2 = max(ground2 + geo[4] * geo[4], ref2)
    gamma: float = geo[7] * gain * math.exp(-0.5 * geo[6] * math.log(dist2 / ref2))
    return gamma


@njit(cache=True)
def _amplitude_kernel(xy: FloatArray, geo: FloatArray, out: FloatArray) -> None:
    """:func:`_amplitude` of each row of ``xy`` ``(n, 2)`` into ``out`` ``(n,)``."""
    for i in range(xy.shape[0]):
        out[i] = _amplitude(xy[i, 0], xy[i, 1], geo)


@njit(cache=True)
def _state_llr_kernel(z: FloatArray, bins: IntArray, leak: FloatArray, x: FloatArray,
                      tau: FloatArray, geo: FloatArray, timing: FloatArray, inv_var: float,
                      out: FloatArray) -> None:
    """Eq. 22 into ``out`` ``(Λ, N)`` from states ``x`` ``(Λ, N, 4)`` and offsets ``tau``: per
    particle ``γ`` (:func:`_amplitude`) and ``m(τ) = ⌈(τ mod T0) f_s / R⌉`` (eq. 16, as
    :meth:`RadioSignal.frame_of`) in the same pass; ``timing = [T0, f_s, R]``."""
    period, rate, hop = timing[0], timing[1], timing[2]
    for lab in range(x.shape[0]):
        cells = _label_cells(z, bins, lab)
        half = _half_energy(leak[lab], inv_var)
        for i in range(x.shape[1]):
            g = _amplitude(x[lab, i, 0], x[lab, i, 2], geo)
            t = tau[lab, i]
            if not 0.0 <= t < period:                 # τ mod T0 is τ itself on [0, T0)
                t = t % period
            out[lab, i] = _particle_llr(cells, leak[lab], g, math.ceil(t * rate / hop),
                                        inv_var, half)


def _reference(z: FloatArray, bins: IntArray, leak: FloatArray, gamma: FloatArray,
               frame: IntArray, var: float) -> FloatArray:
    """NumPy eq. 22 for one label: ``bins``, ``leak`` ``(B,)``, ``gamma``, ``frame`` ``(N,)``."""
    frames = frame[:, None] + np.arange(2)                      # (N, 2)
    valid = (frames >= 0) & (frames < z.shape[0])
    cells = z[np.clip(frames, 0, z.shape[0] - 1)[:, :, None], bins[None, None, :]]  # (N, 2, B)
    nu = gamma[:, None, None] * leak[None, None, :]
    x = cells * nu / var
    llr = -(nu**2) / (2.0 * var) + np.log(i0e(x)) + x
    return np.asarray((llr.sum(axis=2) * valid).sum(axis=1), dtype=np.float64)


def _magnitudes(signal: RadioSignal, z: ArrayLike) -> FloatArray:
    """``z`` as a finite non-negative ``(M, L)`` float array, else InvalidInputError("z")."""
    arr = checks.finite_array("z", z, (signal.frames, signal.fft_size))
    if np.any(arr < 0.0):
        raise InvalidInputError("z", arr.shape, "STFT magnitudes must be non-negative")
    return arr


def _particles(label: int, n_labels: int, gamma: ArrayLike,
               frame: ArrayLike) -> tuple[int, FloatArray, IntArray]:
    lab = checks.count("label", label)
    if lab >= n_labels:
        raise InvalidInputError("label", label, f"must be in [0, {n_labels})")
    g = checks.finite_array("gamma", gamma, (None,))
    if np.any(g < 0.0):
        raise InvalidInputError("gamma", g.shape, "amplitudes must be non-negative")
    f = np.asarray(frame)
    if f.shape != g.shape or (f.size and f.dtype.kind not in "iu"):
        raise InvalidInputError("frame", frame, f"must be {g.size} integer frame indices")
    return lab, g, f.astype(np.int64)


def log_likelihood_ratio(signal: RadioSignal, z: FloatArray, label: int, gamma: FloatArray,
                         frame: IntArray) -> FloatArray:
    """``(N,)`` log ``g_z(x)`` (eq. 22) of ``N`` particles of ``label`` (Numba kernel).

    Parameters
    ----------
    signal
        The signal model (bins, leakage and ``Σ_z``).
    z
        ``(M, L)`` STFT magnitudes.
    label
        The tag label ``λ`` (its frequency index).
    gamma
        ``(N,)`` received amplitudes ``γ_i`` (V).
    frame
        ``(N,)`` pulse frames ``m_i = m(τ_i)``; frames outside ``[0, M)`` contribute nothing.

    Raises
    ------
    InvalidInputError
        On a ``z`` of the wrong shape, non-finite or negative; a label out of range; negative or
        non-finite amplitudes; frames not integers of ``gamma``'s length.
    """
    zz = _magnitudes(signal, z)
    lab, g, f = _particles(label, signal.n_labels, gamma, frame)
    out = np.empty((1, g.size))
    bins = np.ascontiguousarray(signal.tag_bins()[lab:lab + 1], dtype=np.int64)
    leak = np.ascontiguousarray(signal.tag_leakage()[lab:lab + 1], dtype=np.float64)
    _llr_kernel(zz, bins, leak, g[None, :], f[None, :], 1.0 / signal.cell_var, out)
    result: FloatArray = out[0]
    return result


def log_likelihood_ratio_reference(signal: RadioSignal, z: FloatArray, label: int,
                                   gamma: FloatArray, frame: IntArray) -> FloatArray:
    """``(N,)`` log ``g_z(x)`` (eq. 22) in NumPy with ``log I0 = log i0e + x`` (SciPy); the
    reference for :func:`log_likelihood_ratio`, with the same arguments and errors."""
    zz = _magnitudes(signal, z)
    lab, g, f = _particles(label, signal.n_labels, gamma, frame)
    bins = np.asarray(signal.tag_bins()[lab], dtype=np.int64)
    return _reference(zz, bins, np.asarray(signal.tag_leakage()[lab]), g, f, signal.cell_var)


def label_log_likelihoods(signal: RadioSignal, z: FloatArray, x: FloatArray, tau: FloatArray,
                          uav_pose: ArrayLike) -> FloatArray:
    """``(Λ, N)`` log ``g_z`` (eq. 22) of every label's particles seen from ``uav_pose``.

    Parameters
    ----------
    signal
        The signal model; ``Λ = signal.n_labels``.
    z
        ``(M, L)`` STFT magnitudes.
    x
        ``(Λ, N, 4)`` particle states ``[px, vx, py, vy]`` (row ``λ`` holds label ``λ``).
    tau
        ``(Λ, N)`` pulse offsets (s).
    uav_pose
        ``(3,)`` UAV ``(x, y, heading)``.

    Raises
    ------
    InvalidInputError
        On a bad ``z`` (as :func:`log_likelihood_ratio`), states or offsets of the wrong shape,
        or a pose that is not three finite numbers.
    """
    zz = _magnitudes(signal, z)
    n_labels = signal.n_labels
    states = np.asarray(x, dtype=np.float64)
    if states.ndim != 3 or states.shape[0] != n_labels or states.shape[2] != 4:
        raise InvalidInputError("x", states.shape, f"must have shape ({n_labels}, N, 4)")
    offsets = np.asarray(tau, dtype=np.float64)
    if offsets.shape != states.shape[:2]:
        raise InvalidInputError("tau", offsets.shape, f"must have shape {states.shape[:2]}")
    pose = checks.finite_array("uav_pose", uav_pose, (3,))
    out = np.empty(states.shape[:2])
    timing = np.array([signal.period_s, signal.sample_rate_hz, signal.hop], dtype=np.float64)
    _state_llr_kernel(zz, np.ascontiguousarray(signal.tag_bins(), dtype=np.int64),
                      np.ascontiguousarray(signal.tag_leakage(), dtype=np.float64), states,
                      offsets, _geometry(signal, pose), timing, 1.0 / signal.cell_var, out)
    return out


def _geometry(signal: RadioSignal, pose: FloatArray) -> FloatArray:
    """The ``geo`` argument of :func:`_amplitude` for a UAV pose ``(x, y, heading)``."""
    return np.array([pose[0], pose[1], math.cos(pose[2]), math.sin(pose[2]),
                     signal.height_difference_m, signal.reference_distance_m,
                     signal.path_loss_exponent / 2.0, signal.amplitude_v * signal.voltage_gain,
                     signal.back_gain], dtype=np.float64)


def amplitude(signal: RadioSignal, tag_xy: ArrayLike, uav_pose: ArrayLike) -> FloatArray:
    """:meth:`RadioSignal.amplitude` as computed inside the likelihood kernel (Numba): ``γ``
    ``(...)`` of tags at ``tag_xy`` ``(..., 2)`` (m) seen from ``uav_pose`` ``(x, y, heading)``.

    Raises
    ------
    InvalidInputError
        On positions not of shape ``(..., 2)`` or a pose that is not three finite numbers.
    """
    xy = np.asarray(tag_xy, dtype=np.float64)
    if xy.ndim < 1 or xy.shape[-1] != 2:
        raise InvalidInputError("tag_xy", xy.shape, "must have shape (..., 2)")
    pose = checks.finite_array("uav_pose", uav_pose, (3,))
    out = np.empty(xy.shape[:-1])
    _amplitude_kernel(np.ascontiguousarray(xy.reshape(-1, 2)), _geometry(signal, pose),
                      out.reshape(-1))
    return out


def correlated_cells_temper(signal: RadioSignal) -> float:
    """The exponent ``β = |S| / Σ_{b,b'∈S} ρ(b − b')²`` that counts one frame's ``|S|`` cells
    of an influence region as their effective number when the spectrogram is computed from
    the signal (time-domain windows): neighbouring bins of one window then correlate,
    ``ρ(k) = |Σ_n w[n]² e^{−j2πkn/L}| / Σ_n w[n]²`` (0.82 for adjacent bins of the paper's
    4-term Blackman–Harris window), and ``ρ²`` is the correlation of their squared magnitudes
    under noise. Frames do not overlap (``N_w < R``), so they stay independent. Cells simulated
    directly in the STFT domain are independent: use 1 there."""
    w2 = signal.window.astype(np.float64) ** 2
    width = 2 * signal.half_width_bins + 1
    lags = np.arange(-(width - 1), width)
    n = np.arange(w2.size)
    rho = np.abs(np.exp(-2j * np.pi * np.outer(lags, n) / signal.fft_size) @ w2) / w2.sum()
    pairs = width - np.abs(lags)                      # how many (b, b') pairs have each lag
    return float(width / np.sum(pairs * rho**2))
