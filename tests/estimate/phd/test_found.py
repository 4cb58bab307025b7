"""Found-target bookkeeping (paper 004): narrow heavy clusters removed, measurements gated."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.phd import (
    Clusters,
    FoundConfig,
    PHDConfig,
    PHDState,
    gate_found,
    gate_measurements,
    kmeans_clusters,
    mark_found,
)
from searchtrack.models.position_sensor import PositionSensor
from searchtrack.models.range_sensor import RangeBearingElevationSensor

from .helpers import cloud as _cloud
from .helpers import phd_state as _state


def test_found_targets_removed_and_gated() -> None:
    """A narrow heavy cluster is saved as found and its particles removed; gating drops one
    measurement per found target."""
    st = _state(_cloud((200, 200), 300, 2.5, spread=0.5), _cloud((700, 700), 300, 1.0))
    clusters = kmeans_clusters(st, 2, PHDConfig())
    rest, found = mark_found(st, clusters, FoundConfig(radius_m=1.1, mass=2.2), np.empty((0, 2)))
    assert found.shape == (1, 2)
    assert np.linalg.norm(found[0] - [200.0, 200.0]) < 0.5
    assert rest.expected_count() == pytest.approx(1.0)
    z = np.array([[201.0, 200.0], [199.0, 201.0], [500.0, 500.0]])
    keep = gate_measurements(found, z, gate_m=5.0)
    np.testing.assert_array_equal(keep, [False, True, True])


def test_found_config_defaults_and_bad_thresholds() -> None:
    """The defaults are paper 004's 1.1 m, 2.2 and 5 m; a non-positive threshold is refused
    naming it."""
    cfg = FoundConfig()
    assert (cfg.radius_m, cfg.mass, cfg.gate_m, cfg.gate_sigmas) == (1.1, 2.2, 5.0, 0.0)
    for name in ("radius_m", "mass", "gate_m"):
        with pytest.raises(InvalidInputError) as err:
            FoundConfig(**{name: 0.0})
        assert err.value.field == name
    with pytest.raises(InvalidInputError) as err:
        FoundConfig(gate_sigmas=-1.0)
    assert err.value.field == "gate_sigmas"


def _clusters(members: list[int], radii: list[float], masses: list[float]) -> Clusters:
    """Clusters with centres at (10 k, 0) for cluster k."""
    k = len(radii)
    centres = np.column_stack([10.0 * np.arange(k), np.zeros(k)])
    return Clusters(centres, np.array(masses), np.array(radii), np.array(members, dtype=np.int64))


def test_mark_found_keeps_outliers_and_other_clusters() -> None:
    """Only the particles of narrow heavy clusters go; outliers (member −1) and other clusters
    stay; the centres are appended to what was found before."""
    st = PHDState.from_particles(np.arange(10.0).reshape(5, 2), np.ones(5))
    clusters = _clusters([0, 1, -1, 0, 1], radii=[0.5, 0.5], masses=[3.0, 1.0])
    rest, found = mark_found(st, clusters, FoundConfig(), np.array([[7.0, 7.0]]))
    np.testing.assert_array_equal(rest.states, [[2.0, 3.0], [4.0, 5.0], [8.0, 9.0]])
    np.testing.assert_array_equal(found, [[7.0, 7.0], [0.0, 0.0]])


def test_mark_found_without_a_hit_changes_nothing() -> None:
    """No cluster both narrow and heavy: the same state and list come back."""
    st = PHDState.from_particles(np.zeros((2, 2)), np.ones(2))
    before = np.empty((0, 2))
    rest, found = mark_found(st, _clusters([0, 0], [5.0], [3.0]), FoundConfig(), before)
    assert rest is st and found is before


def test_mark_found_needs_clusters_of_the_state() -> None:
    """Clusters over another number of particles are refused naming ``clusters``."""
    st = PHDState.from_particles(np.zeros((2, 2)), np.ones(2))
    with pytest.raises(InvalidInputError, match="clusters"):
        mark_found(st, _clusters([0, 0, 0], [0.1], [3.0]), FoundConfig(), np.empty((0, 2)))


@pytest.mark.parametrize(("gate", "keep"), [(5.0, [False, False]), (1.5, [False, True])])
def test_gating_takes_found_targets_in_order(gate: float, keep: list[bool]) -> None:
    """Found targets at 0 and 1 m, measurements at 0.5 and 3 m: the first target takes the
    0.5 m one; the second the 3 m one (2 m away) only if the gate reaches it."""
    found = np.array([[0.0, 0.0], [1.0, 0.0]])
    z = np.array([[0.5, 0.0], [3.0, 0.0]])
    assert gate_measurements(found, z, gate).tolist() == keep


def test_gating_with_nothing_to_gate() -> None:
    """No measurements give an empty mask; no found targets keep every measurement."""
    assert gate_measurements(np.zeros((1, 2)), np.empty((0, 2)), 5.0).shape == (0,)
    assert gate_measurements(np.empty((0, 2)), np.ones((3, 2)), 5.0).tolist() == [True] * 3


SENSOR_004 = RangeBearingElevationSensor(gain=0.98, fov_m=25.0, sigma=(1.0, 0.02, 0.02))


def _far_detections(n: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` noisy measurements of a target 150 m from the sensor and its found estimate 2 m
    off (as found estimates are after a few long-range detections)."""
    target = np.array([150.0, 0.0, 0.0])
    rng = np.random.default_rng(7)
    z = SENSOR_004.measurement(np.zeros(3), target[None, :]) + \
        np.asarray(SENSOR_004.sigma) * rng.standard_normal((n, 3))
    return z, target + np.array([0.0, 2.0, 0.0])


def test_printed_gate_lets_far_detections_of_a_found_target_through() -> None:
    """With ``gate_sigmas = 0`` :func:`gate_found` is the printed 5 m ball on ``h⁻¹(z)``; a
    found target's detections at 150 m (3 m noise per axis across the line of sight) leave it
    often, which is how a found target's peak re-forms."""
    z, found = _far_detections(400)
    kept = np.array([gate_found(found[None, :], SENSOR_004, np.zeros(3), zi[None, :],
                                FoundConfig())[0] for zi in z])
    expected = [gate_measurements(found[None, :], SENSOR_004.to_position(np.zeros(3),
                                                                         zi[None, :]), 5.0)[0]
                for zi in z]
    np.testing.assert_array_equal(kept, expected)
    assert kept.mean() > 0.2


def test_innovation_gate_takes_far_detections_of_a_found_target() -> None:
    """``gate_sigmas = 4`` gates on the innovation with the sensor's noise and a 5/4 m position
    uncertainty of the found target: the same far detections are removed (≥ 99 %)."""
    z, found = _far_detections(400)
    cfg = FoundConfig(gate_sigmas=4.0)
    kept = np.array([gate_found(found[None, :], SENSOR_004, np.zeros(3), zi[None, :], cfg)[0]
                     for zi in z])
    assert kept.mean() <= 0.01


def test_innovation_gate_is_the_printed_ball_at_short_range_and_keeps_other_targets() -> None:
    """Close to the sensor the innovation gate is about the 5 m ball: a measurement 4 m from the
    found target is removed, one 8 m away is kept; one measurement per found target, in order,
    the smallest innovation first."""
    pose = np.zeros(3)
    found = np.array([[20.0, 0.0, 0.0]])
    cfg = FoundConfig(gate_sigmas=4.0)
    near = SENSOR_004.measurement(pose, np.array([[20.0, 4.0, 0.0]]))
    far = SENSOR_004.measurement(pose, np.array([[20.0, 8.0, 0.0]]))
    exact = SENSOR_004.measurement(pose, found)
    assert gate_found(found, SENSOR_004, pose, near, cfg).tolist() == [False]
    assert gate_found(found, SENSOR_004, pose, far, cfg).tolist() == [True]
    z = np.vstack([near, exact, far])
    assert gate_found(found, SENSOR_004, pose, z, cfg).tolist() == [True, False, True]
    two = np.array([[20.0, 0.0, 0.0], [20.0, 1.0, 0.0]])
    assert gate_found(two, SENSOR_004, pose, z, cfg).tolist() == [False, False, True]


def test_gate_found_with_nothing_to_gate_and_a_sensor_without_innovations() -> None:
    """No found target or no measurement keeps everything; the innovation gate needs a sensor
    with ``innovation_distance`` and is refused naming ``sensor`` otherwise (the printed gate
    works with any sensor)."""
    cfg = FoundConfig(gate_sigmas=4.0)
    z = np.ones((2, 3))
    assert gate_found(np.empty((0, 3)), SENSOR_004, np.zeros(3), z, cfg).tolist() == [True] * 2
    assert gate_found(np.ones((1, 3)), SENSOR_004, np.zeros(3), np.empty((0, 3)),
                      cfg).shape == (0,)
    flat = PositionSensor(0.9, 1.0, 0.0, np.array([[0.0, 10.0], [0.0, 10.0]]))
    found, z2 = np.array([[1.0, 1.0]]), np.array([[1.5, 1.0], [9.0, 9.0]])
    assert gate_found(found, flat, np.zeros(3), z2, FoundConfig()).tolist() == [False, True]
    with pytest.raises(InvalidInputError) as err:
        gate_found(found, flat, np.zeros(3), z2, cfg)
    assert err.value.field == "sensor"
