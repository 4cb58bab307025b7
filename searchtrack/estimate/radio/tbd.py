"""The JMS TBD-LMB filter of Nguyen et al. (§III-C) as a bank of per-label Bernoulli filters.

Each step reads one raw STFT magnitude matrix ``z`` (``M × L``, eq. 11) taken from a UAV pose
and runs the labelled particle LMB recursion of :class:`~.filter.LabelledFilter` (predict with
re-birth, update, resample) with the separable likelihood of eq. 22 on every cell of the
particle's influence region,
:func:`~searchtrack.estimate.radio.likelihood.label_log_likelihoods`. Because the likelihood is
separable (Proposition 1) this is the exact LMB recursion up to the Monte Carlo error.
"""

from __future__ import annotations

from searchtrack.core.types import FloatArray
from searchtrack.estimate.labelled_particles import LabelledParticles
from searchtrack.estimate.radio.birth_proposal import energy_proposal
from searchtrack.estimate.radio.filter import FilterConfig, LabelledFilter
from searchtrack.estimate.radio.likelihood import label_log_likelihoods
from searchtrack.models.radio.scenario import RadioScenario

__all__ = ["FilterConfig", "TbdLmbFilter"]


class TbdLmbFilter(LabelledFilter):
    """Track-before-detect LMB filter over the scenario's known labels (tag frequencies).

    The interface (:meth:`step`, :attr:`state`, :meth:`estimates`, the cardinality read-outs and
    the belief seams) is :class:`~.filter.LabelledFilter`'s.

    Parameters
    ----------
    scenario
        Signal, motion, birth and survival models (:class:`~searchtrack.models.radio.
        RadioScenario`).
    config
        Particle budget and read-out.
    seed
        Seed of the filter's random generator: equal seeds and inputs give equal states.
    """

    def __init__(self, scenario: RadioScenario, config: FilterConfig | None = None, *,
                 seed: int = 0) -> None:
        super().__init__(scenario, config, likelihood=self._log_likelihoods,
                         proposal=self._proposal_of, seed=seed)

    def _proposal_of(self, z: FloatArray, uav_pose: FloatArray) -> FloatArray:
        """Births' τ where the label's bins hold energy (:func:`.birth_proposal.
        energy_proposal`)."""
        del uav_pose
        return energy_proposal(self.scenario.signal, z)

    def _log_likelihoods(self, z: FloatArray, uav_pose: FloatArray,
                         predicted: LabelledParticles) -> FloatArray:
        """``(Λ, N)`` eq. 22 of the predicted particles on the raw magnitudes ``z`` (times the
        configuration's ``temper``)."""
        llr = label_log_likelihoods(self.scenario.signal, z, predicted.x, predicted.tau,
                                    uav_pose)
        if self.config.temper != 1.0:
            llr *= self.config.temper
        return llr
