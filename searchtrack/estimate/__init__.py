"""searchtrack.estimate: belief states, and the seam planners read them through.

- The seam (:mod:`.belief`, :mod:`.particle_belief`): :class:`NodeBelief` (mass on road nodes),
  :class:`TrackBelief` and :class:`BeliefBank` (trackers), :class:`SearchField` (the search
  score per node), :class:`NodePredictor` (the prediction step), :class:`ParticleBelief`
  (weighted particles in open space). Planners accept any object that fits.
- Road search and track (thesis 001): the likelihood-ratio field (Ch. 3), node trackers
  (Ch. 4), their diffusion, scan update, births and deletion; EMD data association (§4.3) as a
  solver family (:mod:`.association`, :mod:`.emd_association`, :mod:`.emd_matrix`,
  :mod:`.transport`).
- Particle PHD filtering (papers 003, 004): :mod:`searchtrack.estimate.phd`.
- Metrics: OSPA, GOSPA, OSPA(2).

A road step: per UAV, :meth:`ScanUpdater.update` (associate, update trackers, update the LRT
with the rest); :meth:`LRTInitiator.initiate` (detect, birth, suppress);
:meth:`TrackerDeleter.delete` (dissolve); then :meth:`LRTPredictor.predict` and
:meth:`TrackerPredictor.predict`.
"""

from __future__ import annotations

from searchtrack.estimate.association import BACKENDS as ASSOCIATION_BACKENDS
from searchtrack.estimate.association import (
    Association,
    AssociationProblem,
    Associator,
)
from searchtrack.estimate.association import solve as associate
from searchtrack.estimate.belief import (
    BeliefBank,
    NodeBelief,
    NodePredictor,
    SearchField,
    SparseNodePredictor,
    TrackBelief,
    entropy_nats,
)
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.emd_association import EMDAssociator
from searchtrack.estimate.emd_matrix import (
    EMD_MATRIX_BACKENDS,
    EMDMatrix,
    EMDMatrixProblem,
    emd_matrix,
    solve_emd_matrix,
)
from searchtrack.estimate.lrt import (
    LikelihoodField,
    LRTInitiator,
    LRTPredictor,
    llr_increment,
    update_likelihood_field,
)
from searchtrack.estimate.metrics import gospa, ospa, ospa2
from searchtrack.estimate.node_tracker import (
    NodeTracker,
    TrackerBank,
    TrackerDeleter,
    TrackerPredictor,
    measurement_density,
    position_log_likelihood,
    update_tracker,
)
from searchtrack.estimate.particle_belief import ParticleBelief, WeightedParticles
from searchtrack.estimate.phd import PHDConfig, PHDState, SensorScan
from searchtrack.estimate.phd import step as phd_step
from searchtrack.estimate.scan import ScanUpdate, ScanUpdater
from searchtrack.estimate.transport import emd, emd_on_graph

__all__ = [
    "ASSOCIATION_BACKENDS",
    "EMD_MATRIX_BACKENDS",
    "Association",
    "AssociationProblem",
    "Associator",
    "BeliefBank",
    "EMDAssociator",
    "EMDMatrix",
    "EMDMatrixProblem",
    "GraphDiffusion",
    "LRTInitiator",
    "LRTPredictor",
    "LikelihoodField",
    "NodeBelief",
    "NodePredictor",
    "NodeTracker",
    "PHDConfig",
    "PHDState",
    "ParticleBelief",
    "ScanUpdate",
    "ScanUpdater",
    "SearchField",
    "SensorScan",
    "SparseNodePredictor",
    "TrackBelief",
    "TrackerBank",
    "TrackerDeleter",
    "TrackerPredictor",
    "WeightedParticles",
    "associate",
    "emd",
    "emd_matrix",
    "emd_on_graph",
    "entropy_nats",
    "gospa",
    "llr_increment",
    "measurement_density",
    "ospa",
    "ospa2",
    "phd_step",
    "position_log_likelihood",
    "solve_emd_matrix",
    "update_likelihood_field",
    "update_tracker",
]
