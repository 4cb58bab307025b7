"""Radio-tagged objects (Nguyen et al.): the JMS TBD-LMB filter on raw STFT magnitudes.

- :mod:`.likelihood`: the separable Rice-over-Rayleigh likelihood (Proposition 1, eq. 22), a
  Numba kernel and its NumPy reference.
- :mod:`searchtrack.estimate.labelled_motion` (beside the belief seam, so that the planners'
  look-ahead can share it): the jump-Markov step (eqs. 46–47) of all particles in one Numba
  pass, draw for draw :func:`searchtrack.models.radio.motion.propagate`.
- :mod:`.particles`: the filters' steps on the labelled particle LMB (one Bernoulli per label,
  vectorised across labels): birth density and prediction (eqs. 24–27 with re-birth). The store
  with its cardinality and mode read-outs, the update (eqs. 29–30) and systematic resampling are
  the belief seam's, :mod:`searchtrack.estimate.labelled_particles`, re-exported here.
- :mod:`.filter`: :class:`LabelledFilter`, predict–update–resample on each measurement with a
  given log-likelihood ratio, its read-outs and belief seams; :class:`FilterConfig`.
- :mod:`.tbd`: :class:`TbdLmbFilter`, the filter with the likelihood of eq. 22.
- :mod:`.dtt`: the detection-then-track baseline (§IV-B): peaks of the spectrogram feed the same
  filter through a detection likelihood (:class:`DttLmbFilter`).
"""

from __future__ import annotations

from searchtrack.estimate.labelled_particles import LabelledParticles, resample, update
from searchtrack.estimate.radio.dtt import (
    Detections,
    DttConfig,
    DttLmbFilter,
    detect_peaks,
    detection_log_likelihoods,
)
from searchtrack.estimate.radio.filter import FilterConfig, LabelledFilter, LogLikelihood
from searchtrack.estimate.radio.likelihood import (
    label_log_likelihoods,
    log_likelihood_ratio,
    log_likelihood_ratio_reference,
)
from searchtrack.estimate.radio.particles import birth_particles, initial_state, predict
from searchtrack.estimate.radio.tbd import TbdLmbFilter

__all__ = [
    "Detections",
    "DttConfig",
    "DttLmbFilter",
    "FilterConfig",
    "LabelledFilter",
    "LabelledParticles",
    "LogLikelihood",
    "TbdLmbFilter",
    "birth_particles",
    "detect_peaks",
    "detection_log_likelihoods",
    "initial_state",
    "label_log_likelihoods",
    "log_likelihood_ratio",
    "log_likelihood_ratio_reference",
    "predict",
    "resample",
    "update",
]
