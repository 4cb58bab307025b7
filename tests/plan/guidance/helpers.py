"""Small road networks and guidance views shared by the guidance tests."""

from __future__ import annotations

import numpy as np

from searchtrack.estimate.lrt import LikelihoodField
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import GuidanceView


def road(coords: list[tuple[float, float]], edges: list[tuple[int, int]]) -> RoadNetwork:
    """The network of ``coords`` and ``edges``, each edge as long as the segment."""
    xy = np.array(coords, dtype=float)
    e = np.array(edges, dtype=np.int64)
    lengths = np.hypot(*(xy[e[:, 0]] - xy[e[:, 1]]).T)
    return RoadNetwork(xy, e, lengths)


def path_road(n: int, step: float = 10.0) -> RoadNetwork:
    """``n`` nodes along the x axis, ``step`` metres apart, joined in order."""
    return road([(i * step, 0.0) for i in range(n)], [(i, i + 1) for i in range(n - 1)])


def view_of(net: RoadNetwork, xy: list[list[float]], trackers: tuple[NodeTracker, ...] = (),
            llr: np.ndarray | None = None) -> GuidanceView:
    """UAVs at ``xy`` heading east at 35 m/s over ``net`` with ``trackers`` and an LRT field
    ``llr`` (zero by default), at time 0."""
    o = len(xy)
    bank = TrackerBank(net.n_nodes, trackers, 1 + max((t.track_id for t in trackers), default=0))
    field = LikelihoodField(np.zeros(net.n_nodes) if llr is None else llr)
    return GuidanceView(net, np.array(xy, dtype=float), np.zeros(o), np.full(o, 35.0), field,
                        bank, 0.0)
