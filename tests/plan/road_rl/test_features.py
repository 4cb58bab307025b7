"""The deep-RL planner's observation (paper 000, Eq. 22–26)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.road_rl.features import RoadFeatures


@dataclass
class _Belief:
    roads: DirectedRoads
    edge: np.ndarray
    s: np.ndarray
    entropy: np.ndarray

    @property
    def n_targets(self) -> int:
        return int(self.edge.shape[0])

    def target_particles(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        w = np.full(self.edge.shape, 1.0 / self.edge.shape[1])
        return self.edge.copy(), self.s.copy(), w

    def target_entropy(self) -> np.ndarray:
        return self.entropy.copy()


@pytest.fixture(scope="module")
def roads() -> DirectedRoads:
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def test_the_vector_has_every_block_in_order(roads: DirectedRoads) -> None:
    f = RoadFeatures(roads, n_targets=2, bins_per_edge=10)
    assert f.n_bins == 24 * 10
    assert f.size == 2 + 2 * 240 + 2 + 9 + (9 * 2 + 24 + 24) + 2 * 4
    edge = np.array([[0] * 4, [5] * 4])
    s = np.array([[5.0, 15.0, 25.0, 95.0], [50.0] * 4])
    obs = f.observe(_Belief(roads, edge, s, np.array([1.0, 3.0])), np.array([[200.0, 0.0]]), 2)
    assert obs.dtype == np.float32 and obs.shape == (f.size,)
    assert np.allclose(obs[:2], [1.0, 0.0])  # the UAV, scaled to the map's box
    hist = obs[2:2 + 480].reshape(2, 240)
    assert np.allclose(hist.sum(axis=1), 240.0)  # scaled so that uniform reads 1 per bin
    assert np.allclose(hist[0, [0, 1, 2, 9]], 60.0) and hist[1, 55] == pytest.approx(240.0)
    gamma = obs[482:484]
    assert gamma[1] > 0.5 > gamma[0]  # the more uncertain target weighs more (Eq. 20)
    assert obs[484 + 2] == 1.0 and obs[484:493].sum() == 1.0  # the UAV's node, one-hot
    slots = obs[-8:]  # node 2 (a corner) has two roads: slots 2 and 3 are empty
    assert np.all(slots[4:] == 0.0) and np.all(slots[:4] >= 0.0)


def test_road_values_are_the_weighted_mass_of_each_leaving_road(roads: DirectedRoads) -> None:
    """Slot k: the Eq. 21 value of the k-th road leaving the node (both directions), and the
    best value of a road after it, scaled by the number of roads."""
    f = RoadFeatures(roads, n_targets=1, include_map=False)
    leaving = np.flatnonzero(roads.tail == 4)  # the centre: four roads
    first = int(leaving[0])
    edge = np.array([[first ^ 1] * 4])  # every particle on the first road, coming back
    s = np.full((1, 4), 10.0)
    obs = f.observe(_Belief(roads, edge, s, np.array([2.0])), np.array([[100.0, 100.0]]), 4)
    gamma = obs[2 + 240]
    slots = obs[-8:]
    assert slots[0] == pytest.approx(gamma * 12.0)  # all the mass, times 24 / 2 roads
    assert np.all(slots[2::2] == 0.0)  # the other roads hold nothing
    # One road after the first: back to it is not allowed (no U-turn), so nothing further.
    assert slots[1] == 0.0
    # One road after any other road from the centre: the first road is never next either.
    off = RoadFeatures(roads, n_targets=1, include_map=False, road_values=False)
    assert off.size == f.size - 8


def test_the_map_block_can_be_left_out(roads: DirectedRoads) -> None:
    assert RoadFeatures(roads, 1, include_map=False).size == 2 + 240 + 1 + 9 + 8


def test_signature_names_what_a_policy_depends_on(roads: DirectedRoads) -> None:
    sig = RoadFeatures(roads, 2, bins_per_edge=5).signature()
    assert sig["n_edges"] == 24 and sig["n_targets"] == 2 and sig["bins_per_edge"] == 5
    assert sig["size"] == RoadFeatures(roads, 2, bins_per_edge=5).size


def test_bad_input_names_the_field(roads: DirectedRoads) -> None:
    for kwargs, field in (({"n_targets": 0}, "n_targets"), ({"n_targets": 1, "n_uavs": 0},
                          "n_uavs"), ({"n_targets": 1, "bins_per_edge": 0}, "bins_per_edge"),
                          ({"n_targets": 1, "gain": -1.0}, "gain")):
        with pytest.raises(InvalidInputError, match=field):
            RoadFeatures(roads, **kwargs)  # type: ignore[arg-type]
    f = RoadFeatures(roads, 2)
    belief = _Belief(roads, np.zeros((2, 3), dtype=np.int64), np.zeros((2, 3)), np.ones(2))
    with pytest.raises(InvalidInputError, match="node"):
        f.observe(belief, np.zeros((1, 2)), 9)
    with pytest.raises(InvalidInputError, match="uav_xy"):
        f.observe(belief, np.full((1, 2), np.nan), 0)
    with pytest.raises(InvalidInputError, match="targets"):
        RoadFeatures(roads, 3).observe(belief, np.zeros((1, 2)), 0)
