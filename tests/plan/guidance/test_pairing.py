"""UAV-to-tracker pairing (thesis 001, Ch. 5): the minimum-distance assignment, the ``Pairing``
record and the peak probability."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.node_tracker import NodeTracker, TrackerBank
from searchtrack.models.roads import RoadNetwork
from searchtrack.plan.guidance import Pairing, pair_uavs

from .helpers import path_road, road


def _bank(net: RoadNetwork, peaks: list[int]) -> TrackerBank:
    trackers = []
    for i, node in enumerate(peaks):
        p = np.full(net.n_nodes, 0.5 / (net.n_nodes - 1))
        p[node] = 0.5
        trackers.append(NodeTracker(p, i))
    return TrackerBank(net.n_nodes, tuple(trackers), len(peaks))

@pytest.mark.parametrize("seed", range(12))
def test_pairing_matches_brute_force(seed: int) -> None:
    """The assignment's summed distance equals the best over every injective pairing."""
    rng = np.random.default_rng(seed)
    net = road([tuple(xy) for xy in rng.uniform(0, 1000, (12, 2))], [(i, i + 1) for i in range(11)])
    n_uav, n_trk = int(rng.integers(1, 5)), int(rng.integers(1, 5))
    peaks = rng.choice(12, n_trk, replace=False).tolist()
    uav = rng.uniform(0, 1000, (n_uav, 2))
    pairing = pair_uavs(net, uav, _bank(net, peaks))
    dist = np.hypot(*(uav[:, None, :] - net.coords[peaks][None, :, :]).transpose(2, 0, 1))
    k = min(n_uav, n_trk)
    best = min(sum(dist[u, t] for u, t in zip(us, ts, strict=True))
               for us in itertools.permutations(range(n_uav), k)
               for ts in itertools.combinations(range(n_trk), k))
    assert pairing.cost_m == pytest.approx(best)
    assert len(pairing.assigned) == k
    got = sum(dist[j, t] for j, t in enumerate(pairing.tracker) if t >= 0)
    assert got == pytest.approx(best)
    for j, t in enumerate(pairing.tracker):
        if t >= 0:
            assert pairing.peak_node[j] == peaks[t] and pairing.track_id[j] == t

def test_pairing_empty_bank() -> None:
    """No trackers: every UAV is unpaired."""
    net = path_road(3)
    pairing = pair_uavs(net, [[0.0, 0.0]], TrackerBank(3))
    assert pairing.tracker == (-1,) and pairing.unpaired == (0,)


def test_nearest_uav_takes_the_only_tracker() -> None:
    """Three UAVs, one tracker peaked at node 5 (x = 50 m): the UAV 10 m away is paired, at
    cost 10 m; the peak probability is the tracker's mass there."""
    net = path_road(10)
    pairing = pair_uavs(net, [[0.0, 0.0], [60.0, 0.0], [50.0, 30.0]], _bank(net, [5]))
    assert pairing.tracker == (-1, 0, -1) and pairing.track_id == (-1, 0, -1)
    assert pairing.peak_node == (-1, 5, -1)
    assert pairing.peak_probability == (0.0, 0.5, 0.0)
    assert pairing.cost_m == pytest.approx(10.0)
    assert pairing.assigned == (1,) and pairing.unpaired == (0, 2)


def test_pairing_reads_track_ids_from_the_bank() -> None:
    """``track_id`` is the tracker's own id, not its index in the bank."""
    net = path_road(4)
    p = np.array([0.1, 0.7, 0.1, 0.1])
    bank = TrackerBank(4, (NodeTracker(p, 7),), 8)
    pairing = pair_uavs(net, [[12.0, 0.0]], bank)
    assert pairing.tracker == (0,) and pairing.track_id == (7,) and pairing.peak_node == (1,)
    assert pairing.peak_probability[0] == pytest.approx(0.7)


def test_pairing_record_checks_itself() -> None:
    """Entries of the wrong length, repeated trackers or indices below −1 raise naming the
    field; ``Pairing.none`` leaves every UAV unpaired."""
    with pytest.raises(InvalidInputError, match="peak_node"):
        Pairing((0, -1), (0, -1), (3,), (0.5, 0.0))
    with pytest.raises(InvalidInputError, match="tracker"):
        Pairing((0, 0), (0, 0), (3, 3), (0.5, 0.5))
    with pytest.raises(InvalidInputError, match="tracker"):
        Pairing((-2,), (-1,), (-1,), (0.0,))
    none = Pairing.none(2)
    assert none.n_uavs == 2 and none.tracker == (-1, -1) and none.assigned == ()
    assert none.unpaired == (0, 1) and none.cost_m == 0.0


def test_pairing_bad_input() -> None:
    """Bad UAV positions or a bank on another network raise naming the field; no UAV gives an
    empty pairing."""
    net = path_road(3)
    with pytest.raises(InvalidInputError, match="uav_xy_m"):
        pair_uavs(net, [0.0, 0.0], TrackerBank(3))
    with pytest.raises(InvalidInputError, match="bank"):
        pair_uavs(net, [[0.0, 0.0]], TrackerBank(4))
    assert pair_uavs(net, np.zeros((0, 2)), _bank(net, [1])).n_uavs == 0
