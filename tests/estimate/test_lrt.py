"""The log-likelihood-ratio tracker: disc update, prediction, detection, birth and suppression."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import (
    GraphDiffusion,
    LikelihoodField,
    LRTInitiator,
    LRTPredictor,
    NodeBelief,
    TrackerBank,
    llr_increment,
    update_likelihood_field,
)
from searchtrack.models import RoadNetwork

from .conftest import path_network


def test_increment_is_m_times_zeta_minus_half_m() -> None:
    """log 𝓛 = −(ζ−m)²/2 + ζ²/2 = m(ζ − m/2) for the thesis's m = 2.9264."""
    m, zeta = 2.9264, 0.7
    assert llr_increment(zeta, m) == pytest.approx(-((zeta - m) ** 2) / 2 + zeta**2 / 2, abs=1e-14)


def test_consecutive_disc_updates_by_hand(path5: RoadNetwork) -> None:
    """m = 3: ζ = 2 on {1, 2} adds 1.5, then ζ = 0.5 on {2, 3} adds −3."""
    field = LikelihoodField.neutral(path5.n_nodes)
    field = update_likelihood_field(field, 2.0, [1, 2], 3.0)
    field = update_likelihood_field(field, 0.5, np.array([2, 3]), 3.0)
    np.testing.assert_allclose(field.llr, [0.0, 1.5, -1.5, -3.0, 0.0], atol=1e-15)


def test_empty_footprint_changes_nothing(path5: RoadNetwork) -> None:
    """A UAV over no road node leaves the field as it was."""
    field = LikelihoodField(np.arange(5.0))
    np.testing.assert_array_equal(update_likelihood_field(field, 3.0, [], 3.0).llr, field.llr)


def test_prediction_on_a_path_by_hand() -> None:
    """φ = (3, 0) on a 2-node path: the mean decays as e^{−τ/C}, the difference as e^{−τ(2+1/C)}."""
    alpha, dt, c = 0.447, 0.3, 50.0
    pred = LRTPredictor(GraphDiffusion.on_network(path_network(2), alpha, dt, decay_c=c))
    out = pred.predict(LikelihoodField(np.array([3.0, 0.0]))).llr
    tau = alpha * dt
    mean, half = 1.5 * math.exp(-tau / c), 1.5 * math.exp(-tau * (2 + 1 / c))
    np.testing.assert_allclose(out, [mean + half, mean - half], atol=1e-14)


def test_neutral_field_is_a_uniform_belief(path5: RoadNetwork) -> None:
    """φ = 0 is uniform as a belief: entropy log n, mass 1; exp(φ) sets the softmax."""
    field = LikelihoodField.neutral(path5.n_nodes)
    assert isinstance(field, NodeBelief)
    assert field.entropy() == pytest.approx(math.log(5))
    assert field.mass() == 1.0
    peaked = LikelihoodField(np.array([0.0, 0.0, math.log(3.0), 0.0, 0.0]))
    np.testing.assert_allclose(peaked.node_probability(), [1 / 7, 1 / 7, 3 / 7, 1 / 7, 1 / 7])
    assert peaked.peak_node() == 2


def test_birth_from_each_connected_super_threshold_component(path5: RoadNetwork) -> None:
    """φ = (0, 11, 12, 3, 10.5) gives trackers on {1, 2} ∝ φ and on {4}, and zeroes those nodes."""
    field = LikelihoodField(np.array([0.0, 11.0, 12.0, 3.0, 10.5]))
    new_field, bank = LRTInitiator(path5, threshold=10.0).initiate(field, TrackerBank(5))
    assert [t.track_id for t in bank] == [0, 1]
    np.testing.assert_allclose(bank[0].probability, [0, 11 / 23, 12 / 23, 0, 0], atol=1e-15)
    np.testing.assert_array_equal(bank[1].probability, [0, 0, 0, 0, 1])
    np.testing.assert_array_equal(new_field.llr, [0.0, 0.0, 0.0, 3.0, 0.0])
    assert bank.next_id == 2


def test_birth_weighted_by_likelihood_ratio(path5: RoadNetwork) -> None:
    """With exp(φ) weights the component {1, 2} splits e^{−1} : 1."""
    field = LikelihoodField(np.array([0.0, 11.0, 12.0, 3.0, 0.0]))
    _, bank = LRTInitiator(path5, weighting="likelihood_ratio").initiate(field, TrackerBank(5))
    e = math.exp(-1.0)
    np.testing.assert_allclose(bank[0].probability, [0, e / (1 + e), 1 / (1 + e), 0, 0])


def test_detection_near_a_live_tracker_is_suppressed_without_birth(path5: RoadNetwork) -> None:
    """With merge_radius_m, a component peaking within it of a tracker's peak is zeroed but
    births nothing; components farther away still birth."""
    field = LikelihoodField(np.array([0.0, 11.0, 12.0, 3.0, 10.5]))
    bank = TrackerBank(5).with_birth([0.0, 0.0, 0.0, 0.1, 0.9])  # peak at node 4 (x = 40 m)
    new_field, out = LRTInitiator(path5, merge_radius_m=5.0).initiate(field, bank)
    assert [t.track_id for t in out] == [0, 1]
    np.testing.assert_allclose(out[1].probability, [0, 11 / 23, 12 / 23, 0, 0], atol=1e-15)
    np.testing.assert_array_equal(new_field.llr, [0.0, 0.0, 0.0, 3.0, 0.0])
    new_field, out = LRTInitiator(path5, merge_radius_m=20.0).initiate(field, bank)
    assert len(out) == 1
    np.testing.assert_array_equal(new_field.llr, [0.0, 0.0, 0.0, 3.0, 0.0])
    with pytest.raises(InvalidInputError, match="merge_radius_m"):
        LRTInitiator(path5, merge_radius_m=-1.0)
    # two components of one step, 30 m apart: one birth (the higher peak) within 35 m
    _, out = LRTInitiator(path5, merge_radius_m=35.0).initiate(field, TrackerBank(5))
    assert len(out) == 1 and out[0].peak_node() == 2
    _, out = LRTInitiator(path5, merge_radius_m=5.0).initiate(field, TrackerBank(5))
    assert len(out) == 2


def test_floor_bounds_negative_evidence_on_updated_nodes(path5: RoadNetwork) -> None:
    """With a floor, repeated misses stop at it on the footprint; nodes outside keep their
    value, and no floor (the thesis) lets φ fall without bound."""
    field = LikelihoodField(np.array([-50.0, 0.0, 0.0, 0.0, 0.0]))
    for _ in range(20):
        field = update_likelihood_field(field, 0.0, [1, 2], 3.0, floor=-20.0)
    np.testing.assert_array_equal(field.llr, [-50.0, -20.0, -20.0, 0.0, 0.0])
    free = update_likelihood_field(LikelihoodField.neutral(5), 0.0, [1], 3.0)
    assert free.llr[1] == pytest.approx(-4.5)
    with pytest.raises(InvalidInputError, match="floor"):
        update_likelihood_field(field, 0.0, [1], 3.0, floor=math.nan)


def test_no_detection_below_threshold(path5: RoadNetwork) -> None:
    """Below φ_max the field and the bank come back unchanged."""
    field = LikelihoodField(np.array([0.0, 9.99, 5.0, 3.0, -2.0]))
    bank = TrackerBank(5)
    assert LRTInitiator(path5).initiate(field, bank) == (field, bank)


def test_bad_lrt_inputs_name_the_field(path5: RoadNetwork) -> None:
    """NaN ζ, an out-of-range footprint node and m ≤ 0 each name their field."""
    field = LikelihoodField.neutral(5)
    cases: list[tuple[tuple[float, list[float], float], str]] = [
        ((math.nan, [1], 3.0), "zeta"), ((1.0, [5], 3.0), "footprint"),
        ((1.0, [-1], 3.0), "footprint"), ((1.0, [1.5], 3.0), "footprint"),
        ((1.0, [1], 0.0), "sensitivity"), ((1.0, [1], math.inf), "sensitivity"),
    ]
    for (zeta, nodes, m), name in cases:
        with pytest.raises(InvalidInputError) as err:
            update_likelihood_field(field, zeta, nodes, m)
        assert err.value.field == name
    with pytest.raises(InvalidInputError) as err:
        LikelihoodField(np.array([0.0, math.nan]))
    assert err.value.field == "llr"
    with pytest.raises(InvalidInputError) as err:
        LRTInitiator(path5, threshold=-1.0)
    assert err.value.field == "threshold"
