"""Point estimates from a particle PHD: measurement attribution and weighted k-means."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.estimate.metrics import ospa
from searchtrack.estimate.phd import (
    PHDConfig,
    PHDState,
    SensorScan,
    extract,
    extract_attribution,
    extract_kmeans,
    kmeans_clusters,
    update,
)
from searchtrack.estimate.phd.state import UpdateRecord

from .helpers import POSE
from .helpers import cloud as _cloud
from .helpers import phd_state as _state
from .helpers import sensor as _sensor


def test_attribution_extraction_finds_detected_targets() -> None:
    """Each well-explained measurement yields one estimate at the posterior mean."""
    st = _state(_cloud((300, 300), 400, 1.0), _cloud((700, 600), 400, 1.0, seed=1))
    z = np.array([[301.0, 299.0], [698.0, 603.0], [50.0, 950.0]])
    est = extract(update(st, [SensorScan(_sensor(), POSE, z)], PHDConfig()), PHDConfig())
    assert len(est) == 2
    assert ospa(est.positions, [[300.0, 300.0], [700.0, 600.0]], c=100.0) < 3.0

def test_kmeans_extraction_separates_clusters() -> None:
    """Weighted k-means with round(λ) clusters finds two separated clouds."""
    st = _state(_cloud((200, 200), 300, 1.1), _cloud((600, 800), 300, 0.9, seed=2))
    est, clusters = extract_kmeans(st, PHDConfig(extraction="kmeans"))
    assert len(est) == 2
    assert ospa(est.positions, [[200.0, 200.0], [600.0, 800.0]], c=100.0) < 2.0
    assert sorted(clusters.masses) == pytest.approx([0.9, 1.1])
    assert np.all(clusters.radii_m < 10.0)


def _with_record(detections: list[tuple[float, float, float]],
                 missed: list[tuple[float, float, float]]) -> PHDState:
    """A one-particle 2-D PHD whose last update recorded ``(x, y, mass)`` detections and
    ``(x, y, existence)`` missed targets."""
    det = np.array(detections, dtype=float).reshape(-1, 3)
    mis = np.array(missed, dtype=float).reshape(-1, 3)
    record = UpdateRecord(det[:, :2].copy(), det[:, 2].copy(), mis[:, :2].copy(),
                          mis[:, 2].copy(), np.zeros((det.shape[0], 2)), np.zeros(det.shape[0]))
    return PHDState(np.zeros((1, 2)), np.ones(1), np.zeros(1, dtype=np.int64),
                    np.full(1, -1, dtype=np.int64), 2, record)


def test_attribution_keeps_masses_above_the_threshold() -> None:
    """Detections with ρ above the threshold are estimates, and missed targets with existence
    above it when report_missed; the others are dropped."""
    st = _with_record([(1, 1, 0.9), (2, 2, 0.3), (3, 3, 0.6)], [(7, 7, 0.7), (8, 8, 0.2)])
    est = extract_attribution(st, PHDConfig())
    np.testing.assert_array_equal(est.positions, [[1, 1], [3, 3], [7, 7]])
    assert est.masses.tolist() == [0.9, 0.6, 0.7] and len(est) == 3
    quiet = extract_attribution(st, PHDConfig(report_missed=False, attribution_threshold=0.8))
    assert quiet.positions.tolist() == [[1.0, 1.0]]


def test_attribution_merges_close_estimates_by_mass() -> None:
    """Estimates closer than merge_radius_m become their mass-weighted mean, heaviest first."""
    st = _with_record([(0, 0, 1.0), (4, 0, 3.0), (50, 0, 0.8)], [])
    est = extract_attribution(st, PHDConfig(merge_radius_m=5.0))
    np.testing.assert_allclose(est.positions, [[3.0, 0.0], [50.0, 0.0]])
    assert est.masses.tolist() == pytest.approx([4.0, 0.8])


def test_kmeans_by_hand_with_an_outlier() -> None:
    """Two heavy particles 2 m apart and a light one far away, k = 1: the centre is their mean,
    mass 4, RMS radius 1 m; the far particle is an outlier (member −1)."""
    x = np.array([[0.0, 0.0], [2.0, 0.0], [500.0, 500.0]])
    st = PHDState.from_particles(x, np.array([2.0, 2.0, 0.5]))
    clusters = kmeans_clusters(st, 1, PHDConfig())
    np.testing.assert_allclose(clusters.centres, [[1.0, 0.0]])
    assert clusters.masses.tolist() == [4.0] and clusters.radii_m == pytest.approx([1.0])
    assert clusters.members.tolist() == [0, 0, -1]


def test_kmeans_with_no_clusters_or_more_than_particles() -> None:
    """k = 0 gives no clusters and every particle an outlier; k is capped at the particle count."""
    st = PHDState.from_particles(np.array([[0.0, 0.0], [100.0, 0.0]]), np.ones(2))
    none = kmeans_clusters(st, 0, PHDConfig())
    assert none.centres.shape == (0, 2) and none.members.tolist() == [-1, -1]
    many = kmeans_clusters(st, 5, PHDConfig())
    assert many.centres.shape == (2, 2) and sorted(many.members.tolist()) == [0, 1]


def test_extract_dispatches_on_the_configured_method() -> None:
    """extract() gives the k-means centres under "kmeans", the attribution estimates otherwise."""
    st = _state(_cloud((200, 200), 100, 1.0))
    cfg = PHDConfig(extraction="kmeans")
    np.testing.assert_array_equal(extract(st, cfg).states, extract_kmeans(st, cfg)[0].states)
    assert len(extract(st, PHDConfig())) == 0  # no update yet: nothing attributed
