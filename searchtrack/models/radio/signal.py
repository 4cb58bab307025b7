"""The radio-tag signal and its time–frequency footprint (Nguyen et al., §III-A, Tables III–IV).

Each tag λ emits an on-off-keyed pulse of width ``P_w`` every ``T0`` seconds at the baseband
frequency ``f_λ`` (eq. 3); the receiver frames the complex baseband at hop ``R = round(P_w f_s/2)``
with an ``N_w``-sample window and takes an ``L``-point DFT (eqs. 8–11), so each pulse covers the
two whole frames ``m(τ) = ⌈τ f_s / R⌉`` and ``m(τ) + 1`` (eq. 16).

Modelling choices (made where the paper is silent or inconsistent):

* Window: the periodic 4-term Blackman–Harris window (main lobe ``N_m = 8`` bins, Table I).
* Leakage: the true DTFT magnitude at the fractional offset ``|W(l − f_λ L/f_s)|``, with
  ``W(δ) = Σ_n w[n] e^{−j2π n δ / L}`` (eq. 14 evaluated off the bin grid), so tones between
  bins are scalloped rather than rounded to the nearest bin (eq. 15).
* Influence region (eq. 20): bins ``S(λ) = round(f_λ L/f_s) + (−h..h)``; they must lie inside
  ``[0, L)`` and the regions of different labels must be disjoint (Proposition 1).
* Calibration (eq. 4): ``γ = A · G_r · G_a(φ) · (d0/d)^(κ/2)`` with the voltage gain
  ``G_r = 10^(G_dB/20)`` and ``κ`` a power path-loss exponent, ``d`` the 3-D distance (the UAV
  flies ``height_difference_m`` above the tags); distances below ``d0`` count as ``d0``.
* Antenna (a 2-element Yagi substitute, azimuth only): amplitude gain
  ``G_a(φ) = b + (1 − b)(1 + cos φ)/2`` with ``b = 10^(−FB/20)``, φ the angle between the UAV
  heading and the ground direction UAV → tag.
* Noise: complex receiver noise of variance ``Σ_η`` (``Σ_η/2`` per component, eq. 48) gives
  cells with ``Σ_z = E_w Σ_η / 2`` per component, ``E_w = Σ w[n]²`` (Lemma 2).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray

ComplexArray = NDArray[np.complex128]

#: Coefficients a0..a3 of the 4-term Blackman–Harris window.
BLACKMAN_HARRIS_4 = (0.35875, 0.48829, 0.14128, 0.01168)
#: Main-lobe width of that window in bins (Table I: 2B for B terms); eq. 19 uses it.
MAIN_LOBE_BINS = 8


def blackman_harris(n: int) -> FloatArray:
    """The periodic 4-term Blackman–Harris window of ``n`` samples (read-only)."""
    phase = 2.0 * np.pi * np.arange(checks.count("n", n, least=1)) / n
    a0, a1, a2, a3 = BLACKMAN_HARRIS_4
    w = a0 - a1 * np.cos(phase) + a2 * np.cos(2.0 * phase) - a3 * np.cos(3.0 * phase)
    return checks.readonly(w, copy=False)


def window_dtft(window: FloatArray, offsets: ArrayLike, fft_size: int) -> ComplexArray:
    """``W(δ) = Σ_n w[n] e^{−j2π n δ / L}`` at the (fractional) bin offsets δ (any shape)."""
    delta = np.asarray(offsets, dtype=np.float64)
    n = np.arange(window.size, dtype=np.float64)
    phase = np.exp(-2j * np.pi * np.multiply.outer(delta, n) / fft_size)
    out: ComplexArray = phase @ window.astype(np.complex128)
    return out


def _frequencies(value: object, sample_rate_hz: float) -> tuple[float, ...]:
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise InvalidInputError("frequencies_hz", value, "must be a sequence of numbers")
    items = tuple(value)
    if not items:
        raise InvalidInputError("frequencies_hz", value, "must name at least one tag")
    freqs = tuple(checks.positive("frequencies_hz", f) for f in items)
    if max(freqs) >= sample_rate_hz / 2.0:
        raise InvalidInputError("frequencies_hz", value,
                                f"must lie below f_s/2 = {sample_rate_hz / 2.0:g} Hz")
    if len(set(freqs)) != len(freqs):
        raise InvalidInputError("frequencies_hz", value, "must be distinct (one per label)")
    return freqs


@dataclass(frozen=True)
class RadioSignal:
    """The tags' pulse trains and the receiver's STFT front end (Tables III–IV).

    Label ``λ`` is the index of its frequency in ``frequencies_hz``. All fields are validated
    at construction (:class:`InvalidInputError` names the field): the frame design of eq. 9
    read as ``f_s/f ≤ N_w < R``, the resolvability condition of eq. 19
    (``N_w ≥ ⌈N_m f_s / Δf⌉``, ``N_m = 8``), ``M·R + N_w ≤ T0·f_s`` (the frames fit in one
    period), ``L ≥ N_w``, and influence regions inside ``[0, L)`` that do not overlap.
    """

    frequencies_hz: tuple[float, ...] = (131e3, 201e3, 401e3, 841e3)
    sample_rate_hz: float = 2e6
    period_s: float = 1.0
    pulse_width_s: float = 0.018
    amplitude_v: float = 0.0059
    path_loss_exponent: float = 3.1068
    reference_distance_m: float = 1.0
    receiver_gain_db: float = 72.0
    noise_var_v2: float = 0.025**2
    frames: int = 111
    fft_size: int = 256
    window_size: int = 256
    half_width_bins: int = 4
    front_to_back_db: float = 10.0
    height_difference_m: float = 29.0

    def __post_init__(self) -> None:
        put = object.__setattr__
        fs = checks.positive("sample_rate_hz", self.sample_rate_hz)
        put(self, "sample_rate_hz", fs)
        put(self, "frequencies_hz", _frequencies(self.frequencies_hz, fs))
        for name in ("period_s", "pulse_width_s", "amplitude_v", "path_loss_exponent",
                     "reference_distance_m", "noise_var_v2"):
            put(self, name, checks.positive(name, getattr(self, name)))
        put(self, "receiver_gain_db", checks.real("receiver_gain_db", self.receiver_gain_db))
        put(self, "front_to_back_db", checks.non_negative("front_to_back_db",
                                                          self.front_to_back_db))
        put(self, "height_difference_m", checks.non_negative("height_difference_m",
                                                             self.height_difference_m))
        put(self, "frames", checks.count("frames", self.frames, least=1))
        put(self, "window_size", checks.count("window_size", self.window_size, least=1))
        put(self, "fft_size", checks.count("fft_size", self.fft_size, least=1))
        put(self, "half_width_bins", checks.count("half_width_bins", self.half_width_bins))
        if self.pulse_width_s > self.period_s:
            raise InvalidInputError("pulse_width_s", self.pulse_width_s,
                                    f"must not exceed the period {self.period_s:g} s")
        self._check_design()

    def _check_design(self) -> None:
        fs, nw, hop = self.sample_rate_hz, self.window_size, self.hop
        lowest = min(self.frequencies_hz)
        if fs / lowest > nw:
            raise InvalidInputError("window_size", nw, f"eq. 9: must hold one period of the "
                                    f"lowest tone, f_s/f = {fs / lowest:.4g} samples")
        if nw >= hop:
            raise InvalidInputError("window_size", nw, f"eq. 9: must be below the hop "
                                    f"R = round(P_w f_s / 2) = {hop}")
        if self.n_labels > 1:
            spacing = float(np.min(np.diff(np.sort(self.frequencies_hz))))
            need = math.ceil(MAIN_LOBE_BINS * fs / spacing)
            if nw < need:
                raise InvalidInputError("window_size", nw, f"eq. 19: tones {spacing:g} Hz apart "
                                        f"need N_w ≥ ⌈8 f_s/Δf⌉ = {need}")
        if self.frames * hop + nw > self.period_s * fs:
            raise InvalidInputError("frames", self.frames, f"M·R + N_w = "
                                    f"{self.frames * hop + nw} samples exceed one period "
                                    f"T0·f_s = {self.period_s * fs:g}")
        if self.fft_size < nw:
            raise InvalidInputError("fft_size", self.fft_size,
                                    f"must be at least the window size {nw}")
        bins = self.tag_bins()
        if bins.min() < 0 or bins.max() >= self.fft_size:
            raise InvalidInputError("frequencies_hz", self.frequencies_hz,
                                    f"influence regions (±{self.half_width_bins} bins) must lie "
                                    f"inside [0, {self.fft_size})")
        if np.unique(bins).size != bins.size:
            raise InvalidInputError("frequencies_hz", self.frequencies_hz,
                                    f"influence regions (±{self.half_width_bins} bins) of "
                                    "different labels overlap (Proposition 1 needs them disjoint)")

    @property
    def n_labels(self) -> int:
        """Number of tags (labels) ``Λ``."""
        return len(self.frequencies_hz)

    @property
    def hop(self) -> int:
        """The hop ``R = round(P_w f_s / 2)`` in samples (eq. 9)."""
        return max(1, round(self.pulse_width_s * self.sample_rate_hz / 2.0))

    @cached_property
    def window(self) -> FloatArray:
        """The ``(N_w,)`` analysis window (periodic 4-term Blackman–Harris), read-only."""
        return blackman_harris(self.window_size)

    @property
    def window_energy(self) -> float:
        """``E_w = Σ w[n]²``."""
        return float(np.sum(self.window**2))

    @property
    def cell_var(self) -> float:
        """``Σ_z = E_w Σ_η / 2``: the variance of each component of an STFT cell (Lemma 2)."""
        return self.window_energy * self.noise_var_v2 / 2.0

    @property
    def receiver_gain(self) -> float:
        """The receiver's voltage gain ``G_r = 10^(G_dB / 20)``."""
        return float(10.0 ** (self.receiver_gain_db / 20.0))

    @property
    def back_gain(self) -> float:
        """The antenna's amplitude gain straight behind, ``b = 10^(−FB/20)``."""
        return float(10.0 ** (-self.front_to_back_db / 20.0))

    def with_noise(self, noise_var_v2: float) -> RadioSignal:
        """A copy with receiver noise variance ``Σ_η = noise_var_v2`` (V², validated > 0)."""
        return dataclasses.replace(self, noise_var_v2=noise_var_v2)

    def _fractional_bins(self) -> FloatArray:
        return np.asarray(self.frequencies_hz) * self.fft_size / self.sample_rate_hz

    def tag_bins(self) -> IntArray:
        """``(Λ, 2h+1)`` bins of each label's influence region ``S(λ)``."""
        centre = np.round(self._fractional_bins()).astype(np.int64)
        offsets = np.arange(-self.half_width_bins, self.half_width_bins + 1, dtype=np.int64)
        return centre[:, None] + offsets[None, :]

    @cached_property
    def _leakage(self) -> FloatArray:
        delta = self.tag_bins() - self._fractional_bins()[:, None]
        return checks.readonly(np.abs(window_dtft(self.window, delta, self.fft_size)),
                               copy=False)

    def tag_leakage(self) -> FloatArray:
        """``(Λ, 2h+1)`` leakage ``|W(l − f_λ L/f_s)|`` at the bins of :meth:`tag_bins`."""
        return self._leakage

    @cached_property
    def _spectra(self) -> ComplexArray:
        bins = np.arange(self.fft_size, dtype=np.float64)
        delta = bins[None, :] - self._fractional_bins()[:, None]
        return checks.readonly(window_dtft(self.window, delta, self.fft_size), copy=False)

    def spectrum(self, label: int) -> ComplexArray:
        """``(L,)`` complex ``W(l − f_λ L/f_s)`` of label ``λ``'s unit tone over all bins."""
        lam = checks.count("label", label)
        if lam >= self.n_labels:
            raise InvalidInputError("label", label, f"must be below {self.n_labels}")
        row: ComplexArray = self._spectra[lam]
        return row

    def frame_of(self, tau_s: ArrayLike) -> IntArray:
        """The first frame ``m(τ) = ⌈((τ mod T0) f_s) / R⌉`` wholly inside each pulse (eq. 16)."""
        tau = np.mod(np.asarray(tau_s, dtype=np.float64), self.period_s)
        return np.ceil(tau * self.sample_rate_hz / self.hop).astype(np.int64)

    def antenna_gain(self, cos_bearing: ArrayLike) -> FloatArray:
        """Amplitude gain ``G_a = b + (1 − b)(1 + cos φ)/2`` (1 ahead, ``b`` behind)."""
        c = np.clip(np.asarray(cos_bearing, dtype=np.float64), -1.0, 1.0)
        b = self.back_gain
        return b + (1.0 - b) * (1.0 + c) / 2.0

    def amplitude(self, tag_xy: ArrayLike, uav_pose: ArrayLike) -> FloatArray:
        """Received amplitude ``γ = A G_r G_a(φ) (d0/d)^(κ/2)`` of tags seen from a UAV pose.

        Parameters
        ----------
        tag_xy
            ``(..., 2)`` ground positions of the tags (m).
        uav_pose
            ``(3,)`` UAV pose ``(x, y, heading)`` (m, m, rad).

        Returns
        -------
        ``(...)`` amplitudes γ (V). A tag straight below the UAV counts as ahead (φ = 0).
        """
        xy = np.asarray(tag_xy, dtype=np.float64)
        if xy.ndim < 1 or xy.shape[-1] != 2:
            raise InvalidInputError("tag_xy", xy.shape, "must have shape (..., 2)")
        pose = checks.finite_array("uav_pose", uav_pose, (3,))
        dx, dy = xy[..., 0] - pose[0], xy[..., 1] - pose[1]
        ground = np.hypot(dx, dy)
        along = dx * math.cos(pose[2]) + dy * math.sin(pose[2])
        safe = np.where(ground > 0.0, ground, 1.0)
        cos_phi = np.where(ground > 0.0, along / safe, 1.0)
        dist = np.maximum(np.hypot(ground, self.height_difference_m), self.reference_distance_m)
        loss = (self.reference_distance_m / dist) ** (self.path_loss_exponent / 2.0)
        out: FloatArray = self.amplitude_v * self.receiver_gain * self.antenna_gain(cos_phi) * loss
        return out
