"""Assimilate one UAV's scan: associated positions update trackers, the rest update the LRT.

This is Algorithm 1 for one UAV ``j``; several UAVs are assimilated by consecutive calls, each
seeing the previous one's posteriors (§3.1: "consecutive measurement updates").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.checks import node_set, points, positive, real
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.association import Association, Associator
from searchtrack.estimate.lrt import LikelihoodField, update_likelihood_field, zeta_increments
from searchtrack.estimate.node_tracker import (
    NodeTracker,
    TrackerBank,
    measurement_density,
    position_log_likelihood,
    update_tracker,
)
from searchtrack.models.roads import RoadNetwork

ASSOCIATED_RADIUS_SD = 3.0
"""With per-node ``ζ``, nodes this many noise s.d. from an associated measurement keep their
LRT value (see :class:`ScanUpdater`)."""


@dataclass(frozen=True, eq=False)
class ScanUpdate:
    """The result of one scan: the new LRT field, the new bank and the association used."""

    field: LikelihoodField
    bank: TrackerBank
    association: Association
    lrt_updated: bool


@dataclass(frozen=True, eq=False)
class ScanUpdater:
    """Route a scan per Algorithm 1, with the associator injected.

    Rule for the LRT (Algorithm 1 lines 15–17, whose "unused trackers" can only mean unused
    *measurements*, plus §3.3's negative information). With one scalar ``ζ`` (the thesis) the
    footprint gets ``m(ζ − m/2)`` when the scan has no position measurement or at least one went
    unassociated; when every position measurement updated a tracker the LRT is left alone, so a
    tracked target does not raise the LRT a second time. With one ``ζ`` per footprint node the
    evidence is local, so the LRT is always updated except on the nodes within
    ``ASSOCIATED_RADIUS_SD`` noise standard deviations of an associated measurement: that
    evidence went to the tracker.

    Parameters
    ----------
    cell_radius_m
        The sensor's resolution cell (per-node ``ζ`` only): nodes within
        ``cell_radius_m + ASSOCIATED_RADIUS_SD · s`` of an associated measurement keep their
        LRT value, since the target's whole cell raised them.
    llr_floor
        Lower bound on ``φ`` on updated nodes (see
        :func:`~searchtrack.estimate.lrt.update_likelihood_field`); ``-inf``: none.
    detection_probability
        ``P_d`` of the negative information given to trackers the scan did not update (0: none).
    """

    network: RoadNetwork
    associator: Associator
    cell_radius_m: float = 0.0
    llr_floor: float = -math.inf
    detection_probability: float = 0.0

    def __post_init__(self) -> None:
        if real("cell_radius_m", self.cell_radius_m) < 0.0:
            raise InvalidInputError("cell_radius_m", self.cell_radius_m, "must be ≥ 0 (m)")
        p = real("detection_probability", self.detection_probability)
        if not 0.0 <= p < 1.0:
            raise InvalidInputError("detection_probability", self.detection_probability,
                                    "must be in [0, 1)")

    def update(
        self,
        field: LikelihoodField,
        bank: TrackerBank,
        *,
        zeta: float | ArrayLike,
        footprint: ArrayLike,
        sensitivity: float,
        positions_m: ArrayLike,
        noise_sd_m: float,
    ) -> ScanUpdate:
        """Assimilate one scan.

        Parameters
        ----------
        zeta
            The scan's LRT measurement ``ζ`` (standard-deviation units): a scalar for the whole
            footprint, or one per footprint node.
        footprint
            Node indices inside the footprint.
        sensitivity
            ``m`` of the sensor (3.9).
        positions_m
            ``(k, 2)`` measured target positions (``k = 0`` when ``ζ ≤ c``).
        noise_sd_m
            Position noise s.d. ``s`` (m).
        """
        n = self.network.n_nodes
        if field.n_nodes != n or bank.n_nodes != n:
            raise InvalidInputError("field", (field.n_nodes, bank.n_nodes),
                                    f"field and bank must be on the network's {n} nodes")
        xy = points("positions_m", positions_m)
        positive("noise_sd_m", noise_sd_m)  # all inputs are checked, whatever the
        nodes = node_set("footprint", footprint, n)
        zeta_increments(zeta, nodes.size, sensitivity)  # scan's route
        association = Association()
        if xy.shape[0] and len(bank):
            ll = position_log_likelihood(self.network, xy, noise_sd_m)
            association = self.associator.associate(bank, measurement_density(ll))
            if any(t >= len(bank) or q >= xy.shape[0] for t, q in association.pairs):
                raise InvalidInputError("association", association.pairs,
                                        f"indices out of range ({len(bank)} trackers, "
                                        f"{xy.shape[0]} measurements)")
            trackers = list(bank.trackers)
            for t, q in association.pairs:
                trackers[t] = update_tracker(trackers[t], ll[q])
            bank = bank.with_trackers(tuple(trackers))
        if self.detection_probability > 0.0 and len(bank) and nodes.size:
            bank = self._negative_information(bank, nodes, {t for t, _ in association.pairs})
        if np.ndim(zeta) == 0:
            lrt_updated = xy.shape[0] == 0 or bool(association.unassociated(xy.shape[0]))
            if lrt_updated:
                field = update_likelihood_field(field, zeta, nodes, sensitivity,
                                                self.llr_floor)
            return ScanUpdate(field, bank, association, lrt_updated)
        per_node = np.asarray(zeta, dtype=np.float64)
        if association.pairs:
            used = xy[[q for _, q in association.pairs]]
            gap = np.linalg.norm(self.network.coords[nodes][:, None, :] - used[None, :, :],
                                 axis=2).min(axis=1)
            keep = gap > self.cell_radius_m + ASSOCIATED_RADIUS_SD * noise_sd_m
            nodes, per_node = nodes[keep], per_node[keep]
        field = update_likelihood_field(field, per_node, nodes, sensitivity, self.llr_floor)
        lrt_updated = bool(nodes.size)
        return ScanUpdate(field, bank, association, lrt_updated)

    def _negative_information(self, bank: TrackerBank, footprint: NDArray[np.int64],
                              associated: set[int]) -> TrackerBank:
        """Trackers this scan did not update saw nothing in the footprint: ``P ∝ P (1 − p_d)``
        there (a rule of this library; the thesis applies none). A tracker wholly inside the
        footprint is left as it is (no mass outside to move to)."""
        keep = 1.0 - self.detection_probability
        trackers = list(bank.trackers)
        for t, tracker in enumerate(trackers):
            if t in associated:
                continue
            p = np.array(tracker.probability, copy=True)
            inside = float(p[footprint].sum())
            if inside <= 0.0 or inside >= 1.0 - 1e-12:
                continue
            p[footprint] *= keep
            trackers[t] = NodeTracker(p / p.sum(), tracker.track_id)
        return bank.with_trackers(tuple(trackers))
