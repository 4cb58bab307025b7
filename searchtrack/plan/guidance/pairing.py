"""UAV-to-tracker pairing (thesis 001, Ch. 5 introduction).

Each UAV is linked to at most one tracker and each tracker to at most one UAV, minimising the
summed Euclidean distance from the UAV to its tracker's peak node ``ψ(max P)``: a rectangular
linear assignment, solved with :func:`scipy.optimize.linear_sum_assignment`. It is recomputed
from scratch every step (the thesis does not say how often). Trackers are read through the
:class:`~searchtrack.estimate.belief.BeliefBank` protocol.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linear_sum_assignment

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.belief import BeliefBank, TrackBelief
from searchtrack.models.roads import RoadNetwork


@dataclass(frozen=True)
class Pairing:
    """Which tracker each UAV serves.

    Parameters
    ----------
    tracker
        Per UAV, the index of its tracker in the bank, or −1 if unpaired.
    track_id
        Per UAV, that tracker's ``track_id``, or −1.
    peak_node, peak_probability
        Per UAV, the tracker's peak node ``ψ(𝒫)`` and value ``𝒫`` (−1 and 0.0 if unpaired).
    cost_m
        The summed UAV-to-peak distance of the pairing (m).
    """

    tracker: tuple[int, ...]
    track_id: tuple[int, ...]
    peak_node: tuple[int, ...]
    peak_probability: tuple[float, ...]
    cost_m: float = 0.0

    def __post_init__(self) -> None:
        n = len(self.tracker)
        for name in ("track_id", "peak_node", "peak_probability"):
            if len(getattr(self, name)) != n:
                raise InvalidInputError(name, getattr(self, name), f"must have {n} entries")
        used = [t for t in self.tracker if t >= 0]
        if len(set(used)) != len(used) or any(t < -1 for t in self.tracker):
            raise InvalidInputError("tracker", self.tracker,
                                    "entries must be −1 or distinct tracker indices")

    @classmethod
    def none(cls, n_uavs: int) -> Pairing:
        """Every UAV unpaired."""
        return cls((-1,) * n_uavs, (-1,) * n_uavs, (-1,) * n_uavs, (0.0,) * n_uavs)

    @property
    def n_uavs(self) -> int:
        """Number of UAVs ``O``."""
        return len(self.tracker)

    @property
    def assigned(self) -> tuple[int, ...]:
        """Indices of the paired UAVs, the set ``𝒥``."""
        return tuple(j for j, t in enumerate(self.tracker) if t >= 0)

    @property
    def unpaired(self) -> tuple[int, ...]:
        """Indices of the UAVs without a tracker."""
        return tuple(j for j, t in enumerate(self.tracker) if t < 0)


def pair_uavs(network: RoadNetwork, uav_xy_m: ArrayLike, bank: BeliefBank) -> Pairing:
    """The pairing of minimum summed distance from each UAV to its tracker's peak node.

    With more trackers than UAVs some trackers go unserved; with fewer, some UAVs stay unpaired.
    Ties are broken deterministically by scipy's solver (it depends on the input order only).
    A tracker's peak probability is its normalized mass on its peak node.

    Raises
    ------
    InvalidInputError
        ``uav_xy_m`` not finite ``(O, 2)`` points, or ``bank`` not a
        :class:`~searchtrack.estimate.belief.BeliefBank` on the network's nodes.
    """
    xy = np.asarray(uav_xy_m, dtype=np.float64)
    if xy.ndim != 2 or xy.shape[1] != 2 or not np.all(np.isfinite(xy)):
        raise InvalidInputError("uav_xy_m", uav_xy_m, "must be finite points of shape (O, 2) (m)")
    if not isinstance(bank, BeliefBank) or bank.n_nodes != network.n_nodes:
        raise InvalidInputError("bank", bank,
                                f"must be a BeliefBank (e.g. a TrackerBank) on {network.n_nodes} "
                                "nodes")
    return pair_checked(network, xy, bank)


def pair_checked(network: RoadNetwork, uav_xy_m: FloatArray, bank: BeliefBank) -> Pairing:
    """:func:`pair_uavs` on inputs already checked, e.g. those of a
    :class:`~searchtrack.plan.guidance.view.GuidanceView`: ``uav_xy_m`` finite ``(O, 2)``
    points, ``bank`` a :class:`~searchtrack.estimate.belief.BeliefBank` on the network's nodes
    (the guidance backends pair every step and skip the protocol check)."""
    n_uav = uav_xy_m.shape[0]
    if n_uav == 0 or len(bank) == 0:
        return Pairing.none(n_uav)
    beliefs = [bank[t] for t in range(len(bank))]
    peaks = np.array([b.peak_node() for b in beliefs], dtype=np.int64)
    diff = uav_xy_m[:, None, :] - network.coords[peaks][None, :, :]
    cost = np.hypot(diff[..., 0], diff[..., 1])
    rows, cols = linear_sum_assignment(cost)
    tracker = [-1] * n_uav
    for j, t in zip(rows.tolist(), cols.tolist(), strict=True):
        tracker[j] = t
    return Pairing(
        tracker=tuple(tracker),
        track_id=tuple(int(beliefs[t].track_id) if t >= 0 else -1 for t in tracker),
        peak_node=tuple(int(peaks[t]) if t >= 0 else -1 for t in tracker),
        peak_probability=tuple(peak_probability(beliefs[t], int(peaks[t])) if t >= 0 else 0.0
                               for t in tracker),
        cost_m=float(cost[rows, cols].sum()),
    )


def peak_probability(belief: TrackBelief, peak: int) -> float:
    """``𝒫``, the normalized mass of ``belief`` on its peak node ``peak``."""
    p = belief.node_probability()
    return float(p[peak]) / belief.mass()
