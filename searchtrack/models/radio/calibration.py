"""Named calibrations of the radio-tag signal model, and the range they give (Nguyen et al.,
§III-A, Tables III–IV).

The paper states the tag's amplitude ``A``, the path-loss exponent ``κ`` and the receiver gain
``G_r = 72 dB`` but not how they meet the STFT cells: whether ``κ`` applies to power or to
amplitude, the antenna's boresight gain and pattern (it defers to its reference [5]) or any
scaling in the SDR. Read literally (``κ`` on the amplitude, no antenna gain), a tag is inaudible
beyond a few tens of metres at the paper's ``Σ_η``. Here ``κ`` is a power exponent (amplitude
``∝ d^(−κ/2)``), the antenna a cardioid with front-to-back ratio ``FB``, and the rest is one
gain ``G_c`` (``calibration_gain_db``, :class:`~searchtrack.models.radio.signal.RadioSignal`):

* ``"fig5"`` (the default of :class:`~searchtrack.models.radio.signal.RadioSignal`):
  ``G_c`` fitted so that the paper's Experiment 1 behaves as its Fig. 5 and Fig. 7 show — every
  object detected while alive and the estimated cardinality following the truth — at the paper's
  ``Σ_η = 0.025² V²``; the fit is ``benchmarks/radio_calibration.py``, which flies Experiment 1
  over a grid of gains and prints each one's range and scores.
* ``"unscaled"``: ``G_c = 0 dB``, the calibration without the open scaling (a tag's cells
  reach 0 dB SNR at a few hundred metres, shorter than the scenario's spread).

:func:`zero_db_range_m` turns a calibration into physics one can read: the ground range at
which the strongest cell of a tag straight ahead of the UAV has a signal-to-noise ratio of
0 dB, ``|γ max_b |W_b||² = 2 Σ_z``.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from searchtrack.core import checks
from searchtrack.core.types import FloatArray
from searchtrack.models.radio.signal import FIG5_GAIN_DB, RadioSignal


@dataclass(frozen=True)
class Calibration:
    """The open quantities of the signal model, as one named choice.

    Parameters
    ----------
    calibration_gain_db
        ``G_c`` (dB): the scaling between the tag's amplitude and the cells.
    front_to_back_db
        The antenna's front-to-back ratio (dB).
    about
        One line on where the values come from.
    """

    calibration_gain_db: float
    front_to_back_db: float
    about: str


CALIBRATIONS: dict[str, Calibration] = {
    "fig5": Calibration(FIG5_GAIN_DB, 10.0, "fitted to the paper's Fig. 5 (Experiment 1: every "
                        "object detected, cardinality following the truth)"),
    "unscaled": Calibration(0.0, 10.0, "no scaling beyond the paper's stated gains"),
}
"""The named calibrations (module docstring); ``"fig5"`` is :class:`RadioSignal`'s default."""

DEFAULT_CALIBRATION = "fig5"
"""The calibration :class:`RadioSignal` holds by default."""


def calibrated(signal: RadioSignal, name: str) -> RadioSignal:
    """``signal`` with the gain and front-to-back ratio of the calibration ``name``."""
    checks.choice("calibration", name, tuple(CALIBRATIONS))
    cal = CALIBRATIONS[name]
    return dataclasses.replace(signal, calibration_gain_db=cal.calibration_gain_db,
                               front_to_back_db=cal.front_to_back_db)


def zero_db_range_m(signal: RadioSignal, *, behind: bool = False) -> FloatArray:
    """``(Λ,)`` ground range (m) at which each tag's strongest cell, seen straight ahead (or,
    with ``behind``, straight behind: the antenna's back gain), has a per-cell SNR of 0 dB; 0
    where it is below 0 dB even straight below the UAV."""
    peak = np.max(np.abs(signal.tag_leakage()), axis=1)               # (Λ,) max_b |W_b|
    noise = math.sqrt(2.0 * signal.cell_var)
    antenna = float(signal.antenna_gain(-1.0 if behind else 1.0))
    # amplitude · peak = noise  ⇔  (d0/d)^(κ/2) = noise / (A G G_a peak)
    loss = noise / (signal.amplitude_v * signal.voltage_gain * antenna * peak)
    d = signal.reference_distance_m * loss ** (-2.0 / signal.path_loss_exponent)
    ground = np.sqrt(np.maximum(d * d - signal.height_difference_m**2, 0.0))
    return np.asarray(np.where(loss <= 1.0, ground, 0.0), dtype=np.float64)
