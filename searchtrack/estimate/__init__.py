"""searchtrack.estimate: beliefs on the road graph — the LRT (Ch. 3) and node trackers (Ch. 4).

A step, in the digest's suggested order: per UAV, :meth:`ScanUpdater.update` (associate, update
trackers, update the LRT with the rest); :meth:`LRTInitiator.initiate` (detect, birth, suppress);
:meth:`TrackerDeleter.delete` (dissolve); then :meth:`LRTPredictor.predict` and
:meth:`TrackerPredictor.predict`.
"""

from __future__ import annotations

from searchtrack.estimate.association import Association, Associator
from searchtrack.estimate.belief import NodeBelief, entropy_nats
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.lrt import (
    LikelihoodField,
    LRTInitiator,
    LRTPredictor,
    llr_increment,
    update_likelihood_field,
)
from searchtrack.estimate.node_tracker import (
    NodeTracker,
    TrackerBank,
    TrackerDeleter,
    TrackerPredictor,
    measurement_density,
    position_log_likelihood,
    update_tracker,
)
from searchtrack.estimate.scan import ScanUpdate, ScanUpdater

__all__ = [
    "Association",
    "Associator",
    "GraphDiffusion",
    "LRTInitiator",
    "LRTPredictor",
    "LikelihoodField",
    "NodeBelief",
    "NodeTracker",
    "ScanUpdate",
    "ScanUpdater",
    "TrackerBank",
    "TrackerDeleter",
    "TrackerPredictor",
    "entropy_nats",
    "llr_increment",
    "measurement_density",
    "position_log_likelihood",
    "update_likelihood_field",
    "update_tracker",
]
