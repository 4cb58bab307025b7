"""The exploration bonus (paper 004 eqs. 9–10) and the refinement values (eq. 11 and the
empty-horizon MI): grid, updates, interpolation and hand-computed values."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.assign.mutual_info import binary_mi
from searchtrack.plan.search import (
    ExplorationBonus,
    centre_probability,
    empty_horizon_mi,
    exploration_value,
)

from .helpers import BOX, CENTRE, SENSOR


def test_bonus_decreases_where_sensed_and_stays_in_unit_interval() -> None:
    """ι starts at 1, falls near the sensed pose, never leaves [0, 1]."""
    fresh = ExplorationBonus(BOX, 10.0)
    assert np.all(fresh.values == 1.0)
    bonus = fresh.updated(SENSOR, CENTRE)
    assert np.all(fresh.values == 1.0)  # immutable: updated returns a new bonus
    assert bonus.at(np.array([[60.0, 60.0, 60.0]]))[0] == pytest.approx(0.02, abs=1e-6)
    assert bonus.at(np.array([[0.0, 0.0, 0.0]]))[0] > 0.9
    assert np.all((bonus.values >= 0.0) & (bonus.values <= 1.0))


def test_grid_covers_the_box() -> None:
    """Axes run from lo to hi with spacing at most the resolution (25 m at 10 m: 4 points)."""
    bonus = ExplorationBonus(np.array([[0.0, 25.0], [0.0, 20.0]]), 10.0)
    np.testing.assert_allclose(bonus.axes[0], [0.0, 25.0 / 3, 50.0 / 3, 25.0])
    np.testing.assert_allclose(bonus.axes[1], [0.0, 10.0, 20.0])
    assert bonus.values.shape == (4, 3) and bonus.points.shape == (12, 2)
    np.testing.assert_allclose(bonus.points[1], [0.0, 10.0])


def test_updates_multiply_the_miss_probabilities() -> None:
    """Eq. (9): after two looks from one pose each grid node holds (1 − π)², π the sensor's
    detection probability of the node."""
    pose = np.array([30.0, 50.0, 70.0])
    bonus = ExplorationBonus(BOX, 20.0).updated(SENSOR, pose).updated(SENSOR, pose)
    pd = SENSOR.detection_probabilities(pose[None, :], bonus.points)[0]
    np.testing.assert_allclose(bonus.values.reshape(-1), (1.0 - pd) ** 2, rtol=1e-12)
    np.testing.assert_allclose(bonus.at(bonus.points[:5]), (1.0 - pd[:5]) ** 2, rtol=1e-12)


def test_planar_bonus_senses_the_ground() -> None:
    """A 2-D bonus puts its grid at z = 0: a pose 25 m up misses a node under it with
    probability 1 − 0.98 e^{−1/2}."""
    bonus = ExplorationBonus(np.array([[0.0, 100.0], [0.0, 100.0]]), 50.0)
    sensed = bonus.updated(SENSOR, np.array([50.0, 50.0, 25.0]))
    assert sensed.at(np.array([[50.0, 50.0]]))[0] == pytest.approx(1.0 - 0.98 * np.exp(-0.5))


def test_interpolation_is_multilinear_and_clamped() -> None:
    """Halfway along a grid edge ι is the mean of the two nodes; outside the box it is the
    value at the nearest boundary point."""
    bonus = ExplorationBonus(BOX, 20.0).updated(SENSOR, CENTRE)
    a, b = np.array([[40.0, 60.0, 60.0]]), np.array([[60.0, 60.0, 60.0]])
    mid = bonus.at(np.array([[50.0, 60.0, 60.0]]))[0]
    assert mid == pytest.approx(0.5 * (bonus.at(a)[0] + bonus.at(b)[0]), rel=1e-12)
    assert bonus.at(np.array([[-50.0, 60.0, 200.0]]))[0] == pytest.approx(
        bonus.at(np.array([[0.0, 60.0, 120.0]]))[0], rel=1e-12)


def test_exploration_value_sums_the_bonus() -> None:
    """Eq. (10): a fresh bonus is 1 everywhere, so E of three poses is 3; after sensing it is
    the sum of ι at the poses."""
    seq = np.array([[10.0, 10.0, 10.0], [60.0, 60.0, 60.0], [100.0, 20.0, 50.0]])
    assert exploration_value(ExplorationBonus(BOX, 10.0), seq) == pytest.approx(3.0)
    sensed = ExplorationBonus(BOX, 10.0).updated(SENSOR, CENTRE)
    assert exploration_value(sensed, seq) == pytest.approx(float(sensed.at(seq).sum()))


def test_centre_probability_by_hand() -> None:
    """Eq. (11): two poses on a centre and one 25 m beside it (one x scale) give
    0.98 + 0.98 + 0.98 e^{−1/2}; no centre gives 0."""
    seq = np.array([CENTRE, CENTRE, [85.0, 60.0, 60.0]])
    expected = 0.98 * (2.0 + np.exp(-0.5))
    assert centre_probability(SENSOR, CENTRE[None, :], seq) == pytest.approx(expected)
    assert centre_probability(SENSOR, np.zeros((0, 3)), seq) == 0.0


def test_empty_horizon_mi_is_the_mi_of_one_merged_measurement() -> None:
    """The MI of 'all empty' equals binary MI with p_d = 1 − Π_j (1 − π_j); no particle, 0."""
    rng = np.random.default_rng(1)
    pos = rng.normal(CENTRE, 10.0, size=(40, 3))
    w = rng.uniform(0.0, 0.1, size=40)
    seq = np.array([CENTRE, [72.0, 60.0, 60.0]])
    pd = SENSOR.detection_probabilities(seq, pos)
    merged = 1.0 - (1.0 - pd[0]) * (1.0 - pd[1])
    assert empty_horizon_mi(SENSOR, pos, w, seq) == pytest.approx(
        binary_mi(merged[None, :], w), rel=1e-12)
    assert empty_horizon_mi(SENSOR, np.zeros((0, 3)), np.zeros(0), seq) == 0.0


def test_bonus_bad_bounds() -> None:
    """Boxes of the wrong shape or with lo ≥ hi raise naming ``bounds``."""
    with pytest.raises(InvalidInputError, match="bounds"):
        ExplorationBonus(np.array([[0.0, 10.0]]), 1.0)
    with pytest.raises(InvalidInputError, match="bounds"):
        ExplorationBonus(np.array([[0.0, 10.0], [5.0, 5.0]]), 1.0)
    with pytest.raises(InvalidInputError, match="resolution_m"):
        ExplorationBonus(BOX, np.inf)
