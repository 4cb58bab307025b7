"""Radio-tagged objects seen by a UAV through an STFT receiver (Nguyen et al., paper 002).

* :mod:`.signal`: the tags' on-off-keyed pulses and the STFT front end (:class:`RadioSignal`,
  §III-A, eqs. 3–19, Tables III–IV), with the amplitude calibration and antenna pattern.
* :mod:`.stft`: measurement simulation, in the time domain or directly in the STFT domain, and
  the noise-free (ideal) spectrogram (eqs. 11–13).
* :mod:`.motion`: jump-Markov WD/CV motion and the τ random walk (:class:`TagMotion`, eqs. 46–47).
* :mod:`.uav`: the UAV's kinematic limits and action primitives (:class:`UavModel`).
* :mod:`.scenario`: the §IV-A scenario (:class:`RadioScenario`), its TOML form and the ground
  truth (:func:`simulate_truth`).
"""

from __future__ import annotations

from searchtrack.models.radio.motion import (
    CV,
    WD,
    TagMotion,
    jump_modes,
    propagate,
    propagate_positions,
    wrap_tau,
)
from searchtrack.models.radio.scenario import RadioScenario, RadioTruth, TagSpec, simulate_truth
from searchtrack.models.radio.signal import (
    BLACKMAN_HARRIS_4,
    MAIN_LOBE_BINS,
    ComplexArray,
    RadioSignal,
    blackman_harris,
    window_dtft,
)
from searchtrack.models.radio.stft import (
    ideal_stft,
    simulate_stft,
    simulate_time_domain,
    stft_magnitude,
)
from searchtrack.models.radio.uav import (
    UavModel,
    fly_heading,
    primitive_headings,
    primitives,
    straight_sweep_heading,
)

__all__ = [
    "BLACKMAN_HARRIS_4",
    "CV",
    "MAIN_LOBE_BINS",
    "WD",
    "ComplexArray",
    "RadioScenario",
    "RadioSignal",
    "RadioTruth",
    "TagMotion",
    "TagSpec",
    "UavModel",
    "blackman_harris",
    "fly_heading",
    "ideal_stft",
    "jump_modes",
    "primitive_headings",
    "primitives",
    "propagate",
    "propagate_positions",
    "simulate_stft",
    "simulate_time_domain",
    "simulate_truth",
    "stft_magnitude",
    "straight_sweep_heading",
    "window_dtft",
    "wrap_tau",
]
