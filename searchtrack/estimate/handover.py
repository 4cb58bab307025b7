"""Identity hand-over on re-detection: a tracker born where a live tracker lost its target takes
that tracker's place and keeps its identity (a rule of this library; thesis 001 has none).

In the thesis a target that a tracker lost is found again by the LRT (§4.1) and gets a *new*
tracker, while the old one lingers, spurious, until its peak falls below ``P_min`` (§4.2): the
same target is then held by two trackers and changes identity. With
:class:`~searchtrack.estimate.lrt.LRTInitiator`'s merge radius a birth never lies next to a live
tracker's peak, so a birth near a live tracker's *mass* is the sign that the tracker's target
drove out from under its peak and that its fixes went to the LRT instead.

The rule, applied to the trackers :meth:`LRTInitiator.initiate
<searchtrack.estimate.lrt.LRTInitiator.initiate>` has just born (highest detection first): an
older live tracker is a *hand-over candidate* for a birth at node ``b`` (the new tracker's peak)
when

- it is *lost*: the caller names it among the ``lost`` trackers (the mission: those without
  an associated fix for :data:`STALE_AFTER_S`), and its peak probability is below
  ``lost_peak`` (1 by default: no condition; the thesis's revisit threshold ``ϱ`` = 0.3 is the
  guidance's own notion of a fading tracker, but at high altitude the position noise keeps
  even a well-tracked peak under it), and
- at least ``min_mass`` of its probability lies within ``reach_m`` road distance of ``b``.

The candidate holding the most mass near ``b`` takes the new tracker's distribution and keeps its
``track_id``; the new tracker is dropped (its identity stays unused). Each older tracker takes
over at most one birth per step. Without a candidate the birth stands.

The reach: a tracker loses its target when the target's fixes stop associating with it, i.e. once
the target is about one EMD gate ``𝓔`` (§4.3, 300 m) from the tracker's mass; the LRT then needs
several looks to reach ``φ_max`` while the target drives on, so re-detections land just beyond
the gate (300–350 m from the lost tracker's peak in experiment-2 runs at 1828.8 m). The mission
therefore uses ``reach_m = 2𝓔``. A tracker still receiving fixes is never a candidate: its
target is where it is, and the birth is another target's.
"""

from __future__ import annotations

import logging
from collections.abc import Collection
from dataclasses import dataclass

import numpy as np

from searchtrack.core.checks import positive, real
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.handover")

Handover = tuple[int, int]
"""One hand-over: ``(kept track_id, dropped track_id of the new tracker)``."""

STALE_AFTER_S = 1.0
"""A tracker without an associated fix (or birth) for this long (s) counts as lost in a
mission: about the looks, 0.3 s apart, the LRT needs to raise a target's node from 0 to
``φ_max`` = 10 (four at ``m²/2 ≈ 3`` per look at 1828.8 m, two at 457.2 m), during which the
target's fixes went to the LRT instead of to the tracker. A tracker in view of its target
misses four fixes in a row with probability ``(1 − P_d)⁴ < 0.0003`` (Table 6.3's ``P_d`` ≥
0.875)."""


@dataclass(frozen=True, eq=False)
class TrackHandover:
    """Hand a re-detected target's new tracker over to the live tracker that lost it.

    Parameters
    ----------
    network
        The road network (road distances in metres along its edges).
    reach_m
        Road distance (m) from the birth node within which the old tracker's mass is counted,
        > 0 (the mission uses twice the association gate ``𝓔``, see above).
    min_mass
        Least fraction of the old tracker's probability within ``reach_m`` of the birth, in
        ``(0, 1]`` (0.5: more likely than not, its target is within reach of the detection).
    lost_peak
        Only trackers whose peak probability is below this take over, in ``(0, 1]`` (1: any).
    """

    network: RoadNetwork
    reach_m: float = 600.0
    min_mass: float = 0.5
    lost_peak: float = 1.0

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        object.__setattr__(self, "reach_m", positive("reach_m", self.reach_m))
        for name in ("min_mass", "lost_peak"):
            value = real(name, getattr(self, name), low=0.0, high=1.0, low_open=True)
            object.__setattr__(self, name, value)

    def near_mass(self, bank: TrackerBank, node: int) -> FloatArray:
        """``(len(bank),)`` probability of each tracker within ``reach_m`` road distance of
        ``node``."""
        if not len(bank):
            return np.zeros(0)
        reach = self.network.shortest_paths(node, limit_m=self.reach_m)[0]
        near = np.flatnonzero(reach <= self.reach_m)
        return np.asarray(bank.probabilities()[:, near].sum(axis=1), dtype=np.float64)

    def hand_over(self, bank: TrackerBank, first_new_id: int,
                  lost: Collection[int] | None = None) -> tuple[TrackerBank, tuple[Handover, ...]]:
        """``bank`` with each new tracker (``track_id ≥ first_new_id``, born this step) handed
        over to a candidate older tracker where there is one (module docstring), and the
        hand-overs made. ``lost`` holds the ``track_id`` of the older trackers that may take a
        birth over (``None``: all of them). The bank's order and ``next_id`` are kept."""
        if bank.n_nodes != self.network.n_nodes:
            raise InvalidInputError("bank", bank.n_nodes,
                                    f"must be on the network's {self.network.n_nodes} nodes")
        ids = np.array([t.track_id for t in bank], dtype=np.int64)
        old = ids < first_new_id
        if not old.any() or old.all():
            return bank, ()
        peaks = np.array([t.peak_probability for t in bank])
        free = old & (peaks < self.lost_peak)
        if lost is not None:
            free &= np.isin(ids, np.fromiter(lost, dtype=np.int64, count=len(lost)))
        trackers: list[NodeTracker | None] = list(bank.trackers)
        done: list[Handover] = []
        for i in np.flatnonzero(~old):
            if not free.any():
                break
            born = bank[int(i)]
            mass = np.where(free, self.near_mass(bank, born.peak_node()), -1.0)
            j = int(np.argmax(mass))  # the first (oldest) on ties
            if mass[j] < self.min_mass:
                continue
            kept = bank[j].track_id
            trackers[j] = NodeTracker(born.probability, kept)
            trackers[int(i)] = None
            free[j] = False
            done.append((kept, born.track_id))
            log.info("tracker %d (%.2f of its mass within %g m) takes over the birth of %d at "
                     "node %d", kept, mass[j], self.reach_m, born.track_id, born.peak_node())
        if not done:
            return bank, ()
        return bank.with_trackers(tuple(t for t in trackers if t is not None)), tuple(done)
