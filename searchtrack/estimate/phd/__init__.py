"""SMC-PHD filter (Vo, Singh & Doucet 2005) with measurement-driven birth (Ristic et al. 2010).

One role, one verb, each a pure function of an immutable :class:`PHDState`: :func:`predict`
(survival, motion, births), :func:`update` (sequential multi-sensor correction), :func:`extract`
(point estimates), :func:`resample` (systematic, with a particle cap); :func:`step` chains them
for one scan. :func:`entropy_per_target` is paper 003's eq. 15; :func:`mark_found`,
:func:`gate_measurements` and :func:`gate_found` are paper 004's found-target bookkeeping.
"""

from __future__ import annotations

from searchtrack.estimate.phd.config import EXTRACTIONS, BirthGrid, PHDConfig, SurvivalMap
from searchtrack.estimate.phd.entropy import entropy_per_target
from searchtrack.estimate.phd.extract import (
    Clusters,
    Estimates,
    extract,
    extract_attribution,
    extract_kmeans,
    kmeans_clusters,
)
from searchtrack.estimate.phd.filter import step
from searchtrack.estimate.phd.found import (
    FoundConfig,
    InnovationSensor,
    gate_found,
    gate_measurements,
    mark_found,
)
from searchtrack.estimate.phd.predict import predict
from searchtrack.estimate.phd.resample import resample, systematic_indices
from searchtrack.estimate.phd.state import NEWBORN, PERSISTENT, PHDState
from searchtrack.estimate.phd.update import SensorScan, update

__all__ = [
    "EXTRACTIONS",
    "NEWBORN",
    "PERSISTENT",
    "BirthGrid",
    "Clusters",
    "Estimates",
    "FoundConfig",
    "InnovationSensor",
    "PHDConfig",
    "PHDState",
    "SensorScan",
    "SurvivalMap",
    "entropy_per_target",
    "extract",
    "extract_attribution",
    "extract_kmeans",
    "gate_found",
    "gate_measurements",
    "kmeans_clusters",
    "mark_found",
    "predict",
    "resample",
    "step",
    "systematic_indices",
    "update",
]
