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
* Calibration (eq. 4): ``γ = A · G_r · G_c · G_a(φ) · (d0/d)^(κ/2)`` with the voltage gain
  ``G_r = 10^(G_dB/20)``, ``κ`` a power path-loss exponent, ``d`` the 3-D distance (the UAV
  flies ``height_difference_m`` above the tags; distances below ``d0`` count as ``d0``) and
  ``G_c = 10^(calibration_gain_db/20)`` the scaling between the tag's amplitude and the STFT
  cells that the paper leaves open (the antenna's boresight gain, the SDR's scaling), fitted
  so that the paper's Experiment 1 behaves as its Fig. 5 shows
  (:mod:`~searchtrack.models.radio.calibration`).
* Antenna (a 2-element Yagi substitute, azimuth only): amplitude gain
  ``G_a(φ) = b + (1 − b)(1 + cos φ)/2`` with ``b = 10^(−FB/20)``, φ the angle between the UAV
  heading and the ground direction UAV → tag.
* Noise: complex receiver noise of variance ``Σ_η`` (``Σ_η/2`` per component, eq. 48) gives
  cells with ``Σ_z = E_w Σ_η / 2`` per component, ``E_w = Σ w[n]²`` (Lemma 2).

Sizes are bounded so that a signal read from a file can neither exhaust memory nor overflow:
see the ``MAX_*`` limits below (the paper's design sits far inside every one).
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

#: Most tags (frequencies) a signal may carry (the paper: 4).
MAX_LABELS = 32
#: Largest DFT length ``L`` and window ``N_w`` (the paper: 256).
MAX_FFT_SIZE = 2**16
#: Most frames ``M`` per period (the paper: 111).
MAX_FRAMES = 2**16
#: Most cells ``M·L`` of one spectrogram (the paper: 28 416).
MAX_CELLS = 2**20
#: Largest ``Λ·L·N_w``, the terms of the tones' spectra over all bins (the paper: 262 144).
MAX_SPECTRUM_TERMS = 2**22
#: Largest sampling rate (Hz) and period ``T0`` (s).
MAX_SAMPLE_RATE_HZ, MAX_PERIOD_S = 1e12, 3600.0
#: Largest receiver noise variance ``Σ_η`` (V²): a noise standard deviation of 1 kV.
MAX_NOISE_VAR_V2 = 1e6
#: Largest magnitude of the gains in dB, and of the pulse amplitude (V).
MAX_GAIN_DB, MAX_AMPLITUDE_V = 200.0, 1e6
#: The calibration gain ``G_c`` (dB) fitted to the paper's Fig. 5
#: (:data:`~searchtrack.models.radio.calibration.CALIBRATIONS`, ``"fig5"``).
FIG5_GAIN_DB = 15.0
#: Largest path-loss exponent κ.
MAX_PATH_LOSS_EXPONENT = 10.0


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


def _bounded_count(name: str, value: object, high: int, low: int = 1) -> int:
    """``value`` as an integer in ``[low, high]``, else :class:`InvalidInputError`."""
    n = checks.count(name, value, least=low)
    if n > high:
        raise InvalidInputError(name, value, f"must be an integer in [{low}, {high}]")
    return n


def _frequencies(value: object, sample_rate_hz: float) -> tuple[float, ...]:
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise InvalidInputError("frequencies_hz", value, "must be a sequence of numbers")
    items = tuple(value)
    if not items:
        raise InvalidInputError("frequencies_hz", value, "must name at least one tag")
    if len(items) > MAX_LABELS:
        raise InvalidInputError("frequencies_hz", f"{len(items)} frequencies",
                                f"at most {MAX_LABELS} tags")
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
    calibration_gain_db: float = FIG5_GAIN_DB
    noise_var_v2: float = 0.025**2
    frames: int = 111
    fft_size: int = 256
    window_size: int = 256
    half_width_bins: int = 4
    front_to_back_db: float = 10.0
    height_difference_m: float = 29.0

    def __post_init__(self) -> None:
        put = object.__setattr__
        real = checks.real
        fs = real("sample_rate_hz", self.sample_rate_hz, low=0.0, low_open=True,
                  high=MAX_SAMPLE_RATE_HZ)
        put(self, "sample_rate_hz", fs)
        put(self, "frequencies_hz", _frequencies(self.frequencies_hz, fs))
        for name, high in (("period_s", MAX_PERIOD_S), ("pulse_width_s", MAX_PERIOD_S),
                           ("amplitude_v", MAX_AMPLITUDE_V),
                           ("path_loss_exponent", MAX_PATH_LOSS_EXPONENT),
                           ("reference_distance_m", math.inf),
                           ("noise_var_v2", MAX_NOISE_VAR_V2)):
            put(self, name, real(name, getattr(self, name), low=0.0, low_open=True, high=high))
        put(self, "receiver_gain_db", real("receiver_gain_db", self.receiver_gain_db,
                                           low=-MAX_GAIN_DB, high=MAX_GAIN_DB))
        put(self, "calibration_gain_db", real("calibration_gain_db", self.calibration_gain_db,
                                              low=-MAX_GAIN_DB, high=MAX_GAIN_DB))
        put(self, "front_to_back_db", real("front_to_back_db", self.front_to_back_db, low=0.0,
                                           high=MAX_GAIN_DB))
        put(self, "height_difference_m", checks.non_negative("height_difference_m",
                                                             self.height_difference_m))
        for name, high in (("frames", MAX_FRAMES), ("window_size", MAX_FFT_SIZE),
                           ("fft_size", MAX_FFT_SIZE)):
            put(self, name, _bounded_count(name, getattr(self, name), high))
        put(self, "half_width_bins", _bounded_count("half_width_bins", self.half_width_bins,
                                                    self.fft_size, low=0))
        if self.pulse_width_s > self.period_s:
            raise InvalidInputError("pulse_width_s", self.pulse_width_s,
                                    f"must not exceed the period {self.period_s:g} s")
        self._check_sizes()
        self._check_design()

    def _check_sizes(self) -> None:
        """The size limits: spectrogram cells, tone spectra, room for the influence regions."""
        m, n_fft, nw, n_labels = self.frames, self.fft_size, self.window_size, self.n_labels
        if m * n_fft > MAX_CELLS:
            raise InvalidInputError("frames", m, f"M·L = {m}·{n_fft} = {m * n_fft} cells per "
                                    f"spectrogram exceed the limit {MAX_CELLS}")
        if n_labels * n_fft * nw > MAX_SPECTRUM_TERMS:
            raise InvalidInputError("fft_size", n_fft, f"Λ·L·N_w = {n_labels}·{n_fft}·{nw} = "
                                    f"{n_labels * n_fft * nw} exceeds the limit "
                                    f"{MAX_SPECTRUM_TERMS} (fewer tags, a shorter DFT or window)")
        width = 2 * self.half_width_bins + 1
        if n_labels * width > n_fft:
            raise InvalidInputError("half_width_bins", self.half_width_bins,
                                    f"{n_labels} disjoint influence regions of {width} bins "
                                    f"cannot fit in L = {n_fft} bins")

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
    def voltage_gain(self) -> float:
        """The whole voltage gain from the tag's amplitude to the cells, ``G_r G_c``."""
        return float(10.0 ** ((self.receiver_gain_db + self.calibration_gain_db) / 20.0))

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
        """Received amplitude ``γ = A G_r G_c G_a(φ) (d0/d)^(κ/2)`` of tags seen from a UAV
        pose.

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
        out: FloatArray = self.amplitude_v * self.voltage_gain * self.antenna_gain(cos_phi) * loss
        return out
