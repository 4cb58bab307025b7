"""Node trackers: diffusion, Gaussian position update, dissolution, entropy and the bank."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate import (
    GraphDiffusion,
    NodeBelief,
    NodeTracker,
    TrackerBank,
    TrackerDeleter,
    TrackerPredictor,
    measurement_density,
    position_log_likelihood,
    update_tracker,
)
from searchtrack.models import RoadNetwork, grid_network

from .conftest import path_network


def test_position_update_by_hand(path3: RoadNetwork) -> None:
    """Prior (0.2, 0.5, 0.3), a fix on node 1 with s = 10 m: the end nodes are weighted e^{−1/2}."""
    ll = position_log_likelihood(path3, [[10.0, 0.0]], 10.0)
    post = update_tracker(NodeTracker(np.array([0.2, 0.5, 0.3])), ll[0])
    e = math.exp(-0.5)
    expected = np.array([0.2 * e, 0.5, 0.3 * e]) / (0.5 + 0.5 * e)
    np.testing.assert_allclose(post.probability, expected, atol=1e-15)
    np.testing.assert_allclose(measurement_density(ll), [[e / (1 + 2 * e), 1 / (1 + 2 * e),
                                                         e / (1 + 2 * e)]], atol=1e-15)


def test_far_measurement_does_not_underflow(path5: RoadNetwork) -> None:
    """A fix 2 km off with s = 5 m still has a posterior: all mass on the nearest support node."""
    prior = NodeTracker(np.array([0.0, 0.5, 0.5, 0.0, 0.0]))
    ll = position_log_likelihood(path5, [2000.0, 0.0], 5.0)
    assert measurement_density(ll)[0, 4] == 1.0
    np.testing.assert_array_equal(update_tracker(prior, ll[0]).probability, [0, 0, 1, 0, 0])


def test_prediction_conserves_each_trackers_mass() -> None:
    """Diffusing four trackers for 50 steps keeps each summing to 1 and spreads them."""
    net = grid_network(4, 4)
    pred = TrackerPredictor(GraphDiffusion.on_network(net, 0.447, 0.3))
    bank = TrackerBank(net.n_nodes)
    for node in (0, 17, 40, 99):
        p = np.zeros(net.n_nodes)
        p[node] = 1.0
        bank = bank.with_birth(p)
    raw = bank.probabilities()
    for _ in range(50):
        bank = pred.predict(bank)
    np.testing.assert_allclose(bank.probabilities().sum(axis=1), 1.0, rtol=1e-14)
    moved = pred.diffusion.propagate(raw.T)
    assert np.abs(moved.sum(axis=0) - 1.0).max() < 1e-13
    assert all(t.peak_probability < 0.5 for t in bank)
    assert [t.track_id for t in bank] == [0, 1, 2, 3]


def test_dissolution_below_p_min() -> None:
    """A spreading tracker is dissolved once its peak falls below P_min; a sharp one survives."""
    net = path_network(200)
    pred = TrackerPredictor(GraphDiffusion.on_network(net, 0.447, 0.3))
    deleter = TrackerDeleter(p_min=0.07)
    sharp = np.zeros(200)
    sharp[[10, 11]] = 0.5
    bank = TrackerBank(200).with_birth(np.eye(200)[100])
    steps = 0
    while len(deleter.delete(bank)):
        bank = pred.predict(bank)
        steps += 1
    # the estimate for an infinite line: below 0.07 after ≈ 36.9 s
    assert 36.0 < steps * 0.3 < 38.0
    kept = deleter.delete(TrackerBank(200).with_birth(sharp).with_birth(np.full(200, 1 / 200)))
    assert [t.track_id for t in kept] == [0]
    assert deleter.delete(kept) is kept


def test_entropy_of_uniform_is_log_n(path5: RoadNetwork) -> None:
    """A uniform tracker on n nodes has entropy log n; a delta has 0."""
    assert NodeTracker(np.full(5, 0.2)).entropy() == pytest.approx(math.log(5))
    assert NodeTracker(np.eye(5)[3]).entropy() == 0.0


def test_bank_is_a_belief_summing_its_trackers() -> None:
    """The bank's mass is its tracker count and its probability the trackers' sum."""
    bank = TrackerBank(4).with_birth([0.0, 1.0, 0.0, 0.0]).with_birth([0.0, 0.5, 0.5, 0.0])
    assert isinstance(bank, NodeBelief) and isinstance(bank[0], NodeBelief)
    np.testing.assert_allclose(bank.node_probability(), [0, 1.5, 0.5, 0])
    assert (bank.mass(), bank.peak_node()) == (2.0, 1)
    assert bank.entropy() == pytest.approx(-(0.75 * math.log(0.75) + 0.25 * math.log(0.25)))
    empty = TrackerBank(4)
    assert (empty.mass(), empty.entropy()) == (0.0, 0.0)
    with pytest.raises(InvalidInputError):
        empty.peak_node()


def test_bad_tracker_inputs_name_the_field(path3: RoadNetwork) -> None:
    """Bad probabilities, positions, noise, likelihoods, P_min and diffusion name their field."""
    cases: list[tuple[Callable[[], object], str]] = [
        (lambda: NodeTracker(np.array([0.5, 0.6, 0.0])), "probability"),
        (lambda: NodeTracker(np.array([-0.1, 0.6, 0.5])), "probability"),
        (lambda: position_log_likelihood(path3, [[math.nan, 0.0]], 5.0), "positions_m"),
        (lambda: position_log_likelihood(path3, [[1.0, 2.0, 3.0]], 5.0), "positions_m"),
        (lambda: position_log_likelihood(path3, [[1.0, 2.0]], 0.0), "noise_sd_m"),
        (lambda: update_tracker(NodeTracker(np.full(3, 1 / 3)), np.zeros(4)), "log_likelihood"),
        (lambda: TrackerDeleter(p_min=1.5), "p_min"),
        (lambda: TrackerPredictor(GraphDiffusion.on_network(path3, 0.4, 0.3, decay_c=50.0)),
         "diffusion"),
        (lambda: TrackerBank(3, (NodeTracker(np.full(3, 1 / 3), 0),), next_id=0), "trackers"),
    ]
    for make, name in cases:
        with pytest.raises(InvalidInputError) as err:
            make()
        assert err.value.field == name
