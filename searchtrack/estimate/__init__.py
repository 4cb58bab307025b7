"""searchtrack.estimate: belief states, and the seam planners read them through.

- The seam (:mod:`.belief`, :mod:`.particle_belief`, :mod:`.labelled_particles`):
  :class:`NodeBelief` (mass on road nodes), :class:`TrackBelief` and :class:`BeliefBank`
  (trackers), :class:`SearchField` (the search score per node), :class:`NodePredictor` (the
  prediction step), :class:`ParticleBelief` (weighted particles in open space),
  :class:`LabelledParticleBelief` (per-label particles and existences, stored plainly as
  :class:`LabelledParticles`). Planners accept any object that fits.
- Road search and track (thesis 001): the likelihood-ratio field (Ch. 3), node trackers
  (Ch. 4), their diffusion, scan update, births, identity hand-over (:mod:`.handover`) and
  deletion; EMD data association (§4.3) as a solver family (:mod:`.association`,
  :mod:`.emd_association`, :mod:`.emd_matrix`, :mod:`.transport`).
- Particle PHD filtering (papers 003, 004): :mod:`searchtrack.estimate.phd`.
- Targets on directed roads (paper 000): the road particle filter and its bank
  (:mod:`.road_pf`), the Rao-Blackwellized filter over association histories (:mod:`.road_rbpf`),
  entropy on road bins (:mod:`.road_entropy`) and batch resampling (:mod:`.road_resampling`).
- Radio-tagged objects (paper 002): the track-before-detect LMB filter on STFT magnitudes,
  :mod:`searchtrack.estimate.radio`, read through :class:`LabelledParticleBelief`.
- Metrics: OSPA (and its localisation and cardinality components), GOSPA, OSPA(2).

A road step: per UAV, :meth:`ScanUpdater.update` (associate, update trackers, update the LRT
with the rest); :meth:`LRTInitiator.initiate` (detect, birth, suppress);
:meth:`TrackerDeleter.delete` (dissolve); then :meth:`LRTPredictor.predict` and
:meth:`TrackerPredictor.predict`.

The names below are imported on first use, so ``import searchtrack.estimate`` stays cheap (the
association solvers load SciPy's optimisers, the transport kernels Numba).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from searchtrack.estimate.association import BACKENDS as ASSOCIATION_BACKENDS
    from searchtrack.estimate.association import Association, AssociationProblem, Associator
    from searchtrack.estimate.association import solve as associate
    from searchtrack.estimate.belief import (
        BeliefBank,
        LabelledParticleBelief,
        NodeBelief,
        NodePredictor,
        RoadParticleBelief,
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
    from searchtrack.estimate.handover import TrackHandover
    from searchtrack.estimate.labelled_particles import LabelledParticles
    from searchtrack.estimate.lrt import (
        LikelihoodField,
        LRTInitiator,
        LRTPredictor,
        llr_increment,
        update_likelihood_field,
    )
    from searchtrack.estimate.metrics import gospa, ospa, ospa2, ospa_components
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
    from searchtrack.estimate.radio import (
        DttConfig,
        DttLmbFilter,
        TbdLmbFilter,
        detect_peaks,
        label_log_likelihoods,
    )
    from searchtrack.estimate.radio import FilterConfig as RadioFilterConfig
    from searchtrack.estimate.road_entropy import RoadBins
    from searchtrack.estimate.road_entropy import combined_entropy as road_combined_entropy
    from searchtrack.estimate.road_entropy import entropy as road_target_entropy
    from searchtrack.estimate.road_entropy import map_positions as road_map_positions
    from searchtrack.estimate.road_filter_bank import RoadFilterBank
    from searchtrack.estimate.road_pf import RoadClouds, RoadParticleFilter
    from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
    from searchtrack.estimate.road_resampling import (
        ResamplePolicy,
        effective_sample_size,
        systematic_indices,
    )
    from searchtrack.estimate.scan import ScanUpdate, ScanUpdater
    from searchtrack.estimate.transport import emd, emd_on_graph

#: Each exported name: (module under searchtrack.estimate, attribute there).
_HOME: dict[str, tuple[str, str]] = {
    "RBPFConfig": ("road_rbpf", "RBPFConfig"),
    "ResamplePolicy": ("road_resampling", "ResamplePolicy"),
    "RoadBins": ("road_entropy", "RoadBins"),
    "RoadClouds": ("road_pf", "RoadClouds"),
    "RoadFilterBank": ("road_filter_bank", "RoadFilterBank"),
    "RoadParticleFilter": ("road_pf", "RoadParticleFilter"),
    "RoadRBPF": ("road_rbpf", "RoadRBPF"),
    "effective_sample_size": ("road_resampling", "effective_sample_size"),
    "road_combined_entropy": ("road_entropy", "combined_entropy"),
    "road_target_entropy": ("road_entropy", "entropy"),
    "road_map_positions": ("road_entropy", "map_positions"),
    "systematic_indices": ("road_resampling", "systematic_indices"),
    "ASSOCIATION_BACKENDS": ("association", "BACKENDS"),
    "Association": ("association", "Association"),
    "AssociationProblem": ("association", "AssociationProblem"),
    "Associator": ("association", "Associator"),
    "BeliefBank": ("belief", "BeliefBank"),
    "EMDAssociator": ("emd_association", "EMDAssociator"),
    "LabelledParticleBelief": ("belief", "LabelledParticleBelief"),
    "LabelledParticles": ("labelled_particles", "LabelledParticles"),
    "RadioFilterConfig": ("radio.tbd", "FilterConfig"),
    "TbdLmbFilter": ("radio.tbd", "TbdLmbFilter"),
    "DttLmbFilter": ("radio.dtt", "DttLmbFilter"),
    "DttConfig": ("radio.dtt", "DttConfig"),
    "detect_peaks": ("radio.dtt", "detect_peaks"),
    "label_log_likelihoods": ("radio.likelihood", "label_log_likelihoods"),
    "ospa_components": ("metrics", "ospa_components"),
    "EMDMatrix": ("emd_matrix", "EMDMatrix"),
    "EMDMatrixProblem": ("emd_matrix", "EMDMatrixProblem"),
    "EMD_MATRIX_BACKENDS": ("emd_matrix", "EMD_MATRIX_BACKENDS"),
    "GraphDiffusion": ("diffusion", "GraphDiffusion"),
    "LRTInitiator": ("lrt", "LRTInitiator"),
    "LRTPredictor": ("lrt", "LRTPredictor"),
    "LikelihoodField": ("lrt", "LikelihoodField"),
    "NodeBelief": ("belief", "NodeBelief"),
    "NodePredictor": ("belief", "NodePredictor"),
    "NodeTracker": ("node_tracker", "NodeTracker"),
    "PHDConfig": ("phd", "PHDConfig"),
    "PHDState": ("phd", "PHDState"),
    "ParticleBelief": ("particle_belief", "ParticleBelief"),
    "RoadParticleBelief": ("belief", "RoadParticleBelief"),
    "ScanUpdate": ("scan", "ScanUpdate"),
    "ScanUpdater": ("scan", "ScanUpdater"),
    "SearchField": ("belief", "SearchField"),
    "SensorScan": ("phd", "SensorScan"),
    "SparseNodePredictor": ("belief", "SparseNodePredictor"),
    "TrackBelief": ("belief", "TrackBelief"),
    "TrackerBank": ("node_tracker", "TrackerBank"),
    "TrackerDeleter": ("node_tracker", "TrackerDeleter"),
    "TrackerPredictor": ("node_tracker", "TrackerPredictor"),
    "TrackHandover": ("handover", "TrackHandover"),
    "WeightedParticles": ("particle_belief", "WeightedParticles"),
    "associate": ("association", "solve"),
    "emd": ("transport", "emd"),
    "emd_matrix": ("emd_matrix", "emd_matrix"),
    "emd_on_graph": ("transport", "emd_on_graph"),
    "entropy_nats": ("belief", "entropy_nats"),
    "gospa": ("metrics", "gospa"),
    "llr_increment": ("lrt", "llr_increment"),
    "measurement_density": ("node_tracker", "measurement_density"),
    "ospa": ("metrics", "ospa"),
    "ospa2": ("metrics", "ospa2"),
    "phd_step": ("phd", "step"),
    "position_log_likelihood": ("node_tracker", "position_log_likelihood"),
    "solve_emd_matrix": ("emd_matrix", "solve_emd_matrix"),
    "update_likelihood_field": ("lrt", "update_likelihood_field"),
    "update_tracker": ("node_tracker", "update_tracker"),
}

__all__ = [
    "ASSOCIATION_BACKENDS",
    "EMD_MATRIX_BACKENDS",
    "Association",
    "AssociationProblem",
    "Associator",
    "BeliefBank",
    "DttConfig",
    "DttLmbFilter",
    "EMDAssociator",
    "EMDMatrix",
    "EMDMatrixProblem",
    "GraphDiffusion",
    "LRTInitiator",
    "LRTPredictor",
    "LabelledParticleBelief",
    "LabelledParticles",
    "LikelihoodField",
    "NodeBelief",
    "NodePredictor",
    "NodeTracker",
    "PHDConfig",
    "PHDState",
    "ParticleBelief",
    "RBPFConfig",
    "RadioFilterConfig",
    "ResamplePolicy",
    "RoadBins",
    "RoadClouds",
    "RoadFilterBank",
    "RoadParticleBelief",
    "RoadParticleFilter",
    "RoadRBPF",
    "ScanUpdate",
    "ScanUpdater",
    "SearchField",
    "SensorScan",
    "SparseNodePredictor",
    "TbdLmbFilter",
    "TrackBelief",
    "TrackHandover",
    "TrackerBank",
    "TrackerDeleter",
    "TrackerPredictor",
    "WeightedParticles",
    "associate",
    "detect_peaks",
    "effective_sample_size",
    "emd",
    "emd_matrix",
    "emd_on_graph",
    "entropy_nats",
    "gospa",
    "label_log_likelihoods",
    "llr_increment",
    "measurement_density",
    "ospa",
    "ospa2",
    "ospa_components",
    "phd_step",
    "position_log_likelihood",
    "road_combined_entropy",
    "road_map_positions",
    "road_target_entropy",
    "solve_emd_matrix",
    "systematic_indices",
    "update_likelihood_field",
    "update_tracker",
]


def __getattr__(name: str) -> Any:
    """The exported ``name``, imported from its module on first use."""
    if name not in _HOME:
        raise AttributeError(f"module 'searchtrack.estimate' has no attribute {name!r}")
    module, attribute = _HOME[name]
    value = getattr(importlib.import_module(f"searchtrack.estimate.{module}"), attribute)
    globals()[name] = value
    return value
