"""Entropy and MAP position of particle clouds on road bins (Eq. 19, Eq. 40)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import road_entropy
from searchtrack.estimate.road_entropy import (
    RoadBins,
    combined_entropy,
    entropy,
    map_bins,
    map_positions,
)
from searchtrack.models import RoadNetwork, grid_network
from searchtrack.models.road_particles import DirectedRoads


@pytest.fixture(scope="module")
def grid3() -> DirectedRoads:
    """The paper's 3×3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def _line(length_m: float) -> DirectedRoads:
    coords = np.array([[0.0, 0.0], [length_m, 0.0]])
    return DirectedRoads(RoadNetwork(coords, np.array([[0, 1]]), np.array([length_m])))


def test_bins_cut_every_directed_edge() -> None:
    """A 12 m road in 5 m bins: 3 bins per direction, the last 2 m long."""
    bins = RoadBins(_line(12.0), 5.0)
    assert bins.n_bins == 6
    np.testing.assert_array_equal(bins.first_bin, [0, 3, 6])
    np.testing.assert_array_equal(bins.index(np.array([0, 0, 0, 1]),
                                             np.array([0.0, 5.0, 12.0, 4.9])), [0, 1, 2, 3])
    edge, s = bins.centre(np.array([0, 2, 4]))
    np.testing.assert_array_equal(edge, [0, 0, 1])
    np.testing.assert_allclose(s, [2.5, 11.0, 7.5])


def test_single_bin_and_uniform_bins(grid3: DirectedRoads) -> None:
    """All mass in one bin: entropy 0; equal mass on k bins: log k."""
    bins = RoadBins(grid3, 5.0)
    edge = np.array([[3] * 4, [3, 3, 5, 7]])
    s = np.array([[1.0, 2.0, 3.0, 4.0], [1.0, 22.0, 1.0, 1.0]])
    h = entropy(bins, edge, s, np.ones((2, 4)))
    np.testing.assert_allclose(h, [0.0, math.log(4)], atol=1e-12)


def test_uniform_cloud_approaches_log_bins(grid3: DirectedRoads) -> None:
    """A large uniform cloud on 480 bins of 5 m has entropy close to log 480."""
    edge, s = grid3.uniform((1, 200_000), np.random.default_rng(0))
    h = entropy(RoadBins(grid3, 5.0), edge, s, np.ones(edge.shape))
    assert h[0] == pytest.approx(math.log(480), abs=0.01)


def test_gaussian_mode_on_1m_bins_matches_the_closed_form() -> None:
    """A Gaussian mode with σ² = 16 m² on 1 m bins has about ½ ln(2πe·16) = 2.805 nats."""
    roads = _line(1000.0)
    s = np.clip(np.random.default_rng(1).normal(500.0, 4.0, 200_000), 0.0, 1000.0)
    h = entropy(RoadBins(roads, 1.0), np.zeros((1, s.size), dtype=np.int64), s[None],
                np.ones((1, s.size)))
    assert h[0] == pytest.approx(0.5 * math.log(2 * math.pi * math.e * 16.0), abs=0.01)


def test_dense_and_sorted_histograms_agree(grid3: DirectedRoads,
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """The bincount and the sort path give the same entropies and MAP bins."""
    rng = np.random.default_rng(2)
    edge, s = grid3.uniform((6, 300), rng)
    w = rng.random((6, 300))
    bins = RoadBins(grid3, 5.0)
    dense = entropy(bins, edge, s, w), map_bins(bins, edge, s, w)
    monkeypatch.setattr(road_entropy, "_DENSE_CELLS_PER_PARTICLE", 0)
    sparse = entropy(bins, edge, s, w), map_bins(bins, edge, s, w)
    np.testing.assert_allclose(dense[0], sparse[0], rtol=1e-12)
    np.testing.assert_array_equal(dense[1], sparse[1])


def test_batch_equals_rows_and_weights_are_normalized(grid3: DirectedRoads) -> None:
    """A batch gives each row's own entropy; scaling a row's weights changes nothing."""
    rng = np.random.default_rng(3)
    edge, s = grid3.uniform((4, 50), rng)
    w = rng.random((4, 50))
    bins = RoadBins(grid3, 1.0)
    batch = entropy(bins, edge, s, w)
    rows = [entropy(bins, edge[i:i + 1], s[i:i + 1], 7.0 * w[i:i + 1])[0] for i in range(4)]
    np.testing.assert_allclose(batch, rows, rtol=1e-12)


def test_combined_entropy_pools_the_targets(grid3: DirectedRoads) -> None:
    """Two targets each in one bin: log 2 if the bins differ, 0 if they are the same."""
    bins = RoadBins(grid3, 5.0)
    w = np.ones((2, 3))
    apart = combined_entropy(bins, np.array([[0] * 3, [6] * 3]), np.full((2, 3), 1.0), w)
    same = combined_entropy(bins, np.array([[0] * 3, [0] * 3]), np.full((2, 3), 1.0), w)
    assert apart == pytest.approx(math.log(2))
    assert same == pytest.approx(0.0, abs=1e-12)


def test_map_position_is_the_densest_bin_centre(grid3: DirectedRoads) -> None:
    """Most mass in the bin [40, 45) of edge 0 gives its centre; ties go to the lower bin."""
    bins = RoadBins(grid3, 5.0)
    edge = np.array([[0, 0, 0, 2], [0, 0, 2, 2]])
    s = np.array([[41.0, 43.0, 60.0, 10.0], [1.0, 2.0, 3.0, 4.0]])
    pos = map_positions(bins, edge, s, np.ones((2, 4)))
    np.testing.assert_allclose(pos[0], grid3.point(np.array([0]), np.array([42.5]))[0])
    assert map_bins(bins, edge, s, np.ones((2, 4)))[1] == bins.index(np.array(0), np.array(1.0))


def test_bad_input_names_the_field(grid3: DirectedRoads) -> None:
    """Shapes, negative weights, positions off the roads and bin lengths are checked."""
    bins = RoadBins(grid3, 5.0)
    edge, s = np.zeros((2, 3), dtype=np.int64), np.ones((2, 3))
    with pytest.raises(InvalidInputError, match=r"^w="):
        entropy(bins, edge, s, -np.ones((2, 3)))
    with pytest.raises(InvalidInputError, match=r"^w="):
        entropy(bins, edge, s, np.ones((2, 2)))
    with pytest.raises(InvalidInputError, match=r"^w="):
        entropy(bins, edge, s, np.zeros((2, 3)))
    with pytest.raises(InvalidInputError, match="edge"):
        entropy(bins, edge[0], s[0], np.ones(3))
    with pytest.raises(InvalidInputError, match=r"^s="):
        entropy(bins, edge, np.full((2, 3), 500.0), np.ones((2, 3)))
    with pytest.raises(InvalidInputError, match="bin_m"):
        RoadBins(grid3, 0.0)


def test_a_cloud_in_one_bin_has_entropy_zero_not_minus_epsilon() -> None:
    """Normalised weights in one bin can add up to 1 + 2.2e-16, whose −p log p is −2.2e-16
    (seen with these 27 weights); an entropy is never negative (planners refuse one)."""
    from searchtrack.models.road_particles import DirectedRoads
    from searchtrack.models.road_synthetic import grid_network

    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    bins = RoadBins(roads, 5.0)
    w = np.array([[0.06608249672407474, 0.8413172796123832, 0.0666900087671014,
                   0.34430997880412517, 0.4302987319478333, 0.9660620807840702,
                   0.562231842228457, 0.25886459317093224, 0.24167571409434496,
                   0.8881183206591798, 0.22586942841732438, 0.1245547058352835,
                   0.2883307570075776, 0.5861230648127328, 0.5540905021732678,
                   0.8097107759127777, 0.5604759520061858, 0.2884212144312105,
                   0.4128963426808927, 0.8181209709709104, 0.6265064624197535,
                   0.9590776426974422, 0.3694044110916809, 0.5526115105212872,
                   0.5939242016131683, 0.84829120827506, 0.14547353818653175]] * 2)
    edge = np.zeros(w.shape, dtype=np.int64)
    s = np.full(w.shape, 1.0)
    assert np.all(entropy(bins, edge, s, w) == 0.0)
    assert combined_entropy(bins, edge, s, w) >= 0.0
