"""Assimilate one UAV's scan: associated positions update trackers, the rest update the LRT.

This is Algorithm 1 for one UAV ``j``; several UAVs are assimilated by consecutive calls, each
seeing the previous one's posteriors (§3.1: "consecutive measurement updates").
"""

from __future__ import annotations

from dataclasses import dataclass

from numpy.typing import ArrayLike

from searchtrack.errors import InvalidInputError
from searchtrack.estimate._checks import node_set, points, real
from searchtrack.estimate.association import Association, Associator
from searchtrack.estimate.lrt import LikelihoodField, llr_increment, update_likelihood_field
from searchtrack.estimate.node_tracker import (
    TrackerBank,
    measurement_density,
    position_log_likelihood,
    update_tracker,
)
from searchtrack.models.roads import RoadNetwork


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

    Rule for the LRT (Algorithm 1 lines 15–17, read with the digest's erratum "unused
    *measurements*", plus §3.3's negative information): the footprint gets ``m(ζ − m/2)``
    when the scan has no position measurement or at least one went unassociated; when every
    position measurement updated a tracker the LRT is left alone, so a tracked target does not
    raise the LRT a second time.
    """

    network: RoadNetwork
    associator: Associator

    def update(
        self,
        field: LikelihoodField,
        bank: TrackerBank,
        *,
        zeta: float,
        footprint: ArrayLike,
        sensitivity: float,
        positions_m: ArrayLike,
        noise_sd_m: float,
    ) -> ScanUpdate:
        """Assimilate one scan.

        Parameters
        ----------
        zeta
            The scan's scalar LRT measurement ``ζ`` (standard-deviation units).
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
        real("noise_sd_m", noise_sd_m, positive=True)  # all inputs are checked, whatever the
        llr_increment(zeta, sensitivity)  # scan's route
        nodes = node_set("footprint", footprint, n)
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
        lrt_updated = xy.shape[0] == 0 or bool(association.unassociated(xy.shape[0]))
        if lrt_updated:
            field = update_likelihood_field(field, zeta, nodes, sensitivity)
        return ScanUpdate(field, bank, association, lrt_updated)
