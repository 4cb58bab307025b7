"""Spectrogram measurements of radio tags: simulated, and noise-free (Nguyen et al., eqs. 8–18).

A measurement ``z`` is the ``(M, L)`` magnitude ``|Y^(m)[l]|`` of the STFT of one period of
complex baseband (eq. 11). Two simulators are offered:

* :func:`simulate_time_domain` (physical): draws only the ``M·N_w`` samples inside the
  windows; a tag's tone is present where the sample time lies in its pulse
  ``[τ, τ + P_w)`` (modulo ``T0``), so windows on the pulse edges get partial signal, and a
  pulse that wraps past ``T0`` shows at the start of the period. Complex noise has ``Σ_η/2``
  per component; the window makes neighbouring bins of a frame correlated.
* :func:`simulate_stft` (model-consistent): ``Y = Σ G + H`` (eqs. 12–13) with
  ``G = γ e^{jψ} W(l − f_λ L/f_s)`` on the tag's influence region — frames
  ``{m(τ), m(τ)+1} ∩ [0, M)``, bins ``S(λ)`` — and ``H`` i.i.d. complex Gaussian with ``Σ_z``
  per component, exactly the model behind the likelihood of eq. 22.

Both draw one uniform phase ψ per tag per period; a tag's phase advances by ``2π f_λ R / f_s``
from one frame to the next, as it does in the time domain. :func:`ideal_stft` is the noise-free
``|Σ G|`` (with ψ = 0) used as the predicted ideal measurement in planning.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.radio.signal import ComplexArray, RadioSignal


def stft_magnitude(signal: RadioSignal, frames: ComplexArray) -> FloatArray:
    """``(k, L)`` magnitudes ``|Σ_n y[n] w[n] e^{−j2π n l/L}|`` of ``(k, N_w)`` sample frames.

    The per-frame factor ``e^{−j2π m R l/L}`` of eq. 11 has unit modulus and is left out.
    """
    arr = np.asarray(frames)
    if arr.ndim != 2 or arr.shape[1] != signal.window_size:
        raise InvalidInputError("frames", arr.shape,
                                f"must have shape (k, {signal.window_size})")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError("frames", "...", "must be finite")
    spectrum = np.fft.fft(arr * signal.window, n=signal.fft_size, axis=1)
    out: FloatArray = np.abs(spectrum)
    return out


def _tags(signal: RadioSignal, tag_xy: ArrayLike, tag_label: ArrayLike,
          tag_tau: ArrayLike, uav_pose: ArrayLike) -> tuple[IntArray, FloatArray, FloatArray]:
    """Validated ``(labels, taus, amplitudes γ)`` of ``n`` tags."""
    xy = checks.points("tag_xy", tag_xy)
    labels = checks.index_array("tag_label", np.reshape(tag_label, -1), signal.n_labels)
    tau = checks.finite_array("tag_tau", np.reshape(np.asarray(tag_tau, dtype=np.float64), -1),
                              (None,))
    if not labels.size == tau.size == xy.shape[0]:
        raise InvalidInputError("tag_label", tag_label,
                                f"tag_xy, tag_label and tag_tau must describe the same tags "
                                f"({xy.shape[0]}, {labels.size}, {tau.size})")
    gamma = signal.amplitude(xy, checks.finite_array("uav_pose", uav_pose, (3,)))
    return labels, tau, gamma


def _signal_cells(signal: RadioSignal, labels: IntArray, tau: FloatArray, gamma: FloatArray,
                  phase: FloatArray) -> ComplexArray:
    """``(M, L)`` noise-free ``Σ G`` over the tags' influence regions (eq. 13)."""
    out = np.zeros((signal.frames, signal.fft_size), dtype=np.complex128)
    bins = signal.tag_bins()
    first = signal.frame_of(tau)
    advance = 2.0 * np.pi * np.asarray(signal.frequencies_hz) * signal.hop / signal.sample_rate_hz
    for lam, m0, g, psi in zip(labels, first, gamma, phase, strict=True):
        cols = bins[lam]
        tone = g * signal.spectrum(int(lam))[cols]
        for m in (m0, m0 + 1):
            if 0 <= m < signal.frames:
                out[m, cols] += tone * np.exp(1j * (psi + advance[lam] * m))
    return out


def simulate_stft(signal: RadioSignal, tag_xy: ArrayLike, tag_label: ArrayLike,
                  tag_tau: ArrayLike, uav_pose: ArrayLike,
                  rng: np.random.Generator) -> FloatArray:
    """``(M, L)`` measurement drawn in the STFT domain: ``|Σ G + H|``, ``H`` i.i.d. ``Σ_z``.

    Parameters
    ----------
    signal
        Signal and receiver.
    tag_xy, tag_label, tag_tau
        ``(n, 2)`` positions (m), ``(n,)`` labels and ``(n,)`` pulse offsets (s) of the tags.
    uav_pose
        ``(3,)`` UAV pose ``(x, y, heading)``.
    rng
        Source of the phases and the noise.
    """
    labels, tau, gamma = _tags(signal, tag_xy, tag_label, tag_tau, uav_pose)
    checks.generator("rng", rng)
    phase = rng.uniform(0.0, 2.0 * np.pi, labels.size)
    cells = _signal_cells(signal, labels, tau, gamma, phase)
    shape = (signal.frames, signal.fft_size)
    sd = np.sqrt(signal.cell_var)
    noise = sd * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    out: FloatArray = np.abs(cells + noise)
    return out


def ideal_stft(signal: RadioSignal, tag_xy: ArrayLike, tag_label: ArrayLike, tag_tau: ArrayLike,
               uav_pose: ArrayLike) -> FloatArray:
    """``(M, L)`` noise-free magnitude ``|Σ G|`` (phases 0): ``γ|W|`` on each tag's cells."""
    labels, tau, gamma = _tags(signal, tag_xy, tag_label, tag_tau, uav_pose)
    out: FloatArray = np.abs(_signal_cells(signal, labels, tau, gamma, np.zeros(labels.size)))
    return out


def simulate_time_domain(signal: RadioSignal, tag_xy: ArrayLike, tag_label: ArrayLike,
                         tag_tau: ArrayLike, uav_pose: ArrayLike,
                         rng: np.random.Generator) -> FloatArray:
    """``(M, L)`` measurement from simulated complex baseband samples inside the M windows.

    Each tag adds ``γ e^{jψ} e^{j2π f_λ t}`` at the sample times ``t = (mR + n)/f_s`` that lie
    in its pulse (``(t − τ) mod T0 < P_w``); the noise has ``Σ_η/2`` per component; the frames
    then pass through :func:`stft_magnitude`. Parameters as :func:`simulate_stft`.
    """
    labels, tau, gamma = _tags(signal, tag_xy, tag_label, tag_tau, uav_pose)
    checks.generator("rng", rng)
    phase = rng.uniform(0.0, 2.0 * np.pi, labels.size)
    starts = signal.hop * np.arange(signal.frames)
    t = (starts[:, None] + np.arange(signal.window_size)[None, :]) / signal.sample_rate_hz
    shape = t.shape
    sd = np.sqrt(signal.noise_var_v2 / 2.0)
    samples = sd * (rng.standard_normal(shape) + 1j * rng.standard_normal(shape))
    for lam, tau_k, g, psi in zip(labels, tau, gamma, phase, strict=True):
        on = np.mod(t - tau_k, signal.period_s) < signal.pulse_width_s
        freq = signal.frequencies_hz[lam]
        samples += np.where(on, g * np.exp(1j * (psi + 2.0 * np.pi * freq * t)), 0.0)
    return stft_magnitude(signal, samples)
