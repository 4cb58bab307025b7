"""The belief seam: Shannon entropy of a node mass, and the protocols planners check against."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.estimate import GraphDiffusion, LikelihoodField, NodeTracker, TrackerBank
from searchtrack.estimate.belief import (
    BeliefBank,
    NodeBelief,
    NodePredictor,
    SearchField,
    SparseNodePredictor,
    TrackBelief,
    entropy_nats,
)
from searchtrack.models import RoadNetwork


@pytest.mark.parametrize("n", [1, 2, 7])
def test_entropy_of_uniform_mass_is_log_n(n: int) -> None:
    """A uniform mass on n nodes has entropy log n, whatever its total."""
    assert entropy_nats(np.full(n, 3.0)) == pytest.approx(math.log(n), abs=1e-15)


def test_entropy_by_hand() -> None:
    """(1, 3) normalises to (¼, ¾): H = −¼ log ¼ − ¾ log ¾; zero entries add nothing."""
    expected = -(0.25 * math.log(0.25) + 0.75 * math.log(0.75))
    assert entropy_nats(np.array([1.0, 3.0])) == pytest.approx(expected, rel=1e-15)
    assert entropy_nats(np.array([0.0, 1.0, 0.0, 3.0])) == pytest.approx(expected, rel=1e-15)


@pytest.mark.parametrize("mass", [np.zeros(3), np.zeros(0), np.array([1.0, -1.0])])
def test_entropy_without_mass_is_zero(mass: np.ndarray) -> None:
    """An all-zero, empty or zero-total mass has entropy 0 (not NaN)."""
    assert entropy_nats(mass) == 0.0


def test_entropy_of_a_point_mass_is_zero() -> None:
    """All mass on one node: no uncertainty."""
    assert entropy_nats(np.array([0.0, 5.0, 0.0])) == 0.0


class _Belief:
    """A test-local node belief with everything NodeBelief asks for."""

    n_nodes = 2

    def node_probability(self) -> np.ndarray:
        return np.array([0.5, 0.5])

    def mass(self) -> float:
        return 1.0

    def peak_node(self) -> int:
        return 0

    def entropy(self) -> float:
        return math.log(2.0)


class _NoEntropy:
    """A node belief missing ``entropy``."""

    n_nodes = 2

    def node_probability(self) -> np.ndarray:
        return np.array([0.5, 0.5])

    def mass(self) -> float:
        return 1.0

    def peak_node(self) -> int:
        return 0


def test_protocols_check_the_members() -> None:
    """A class with every member is a NodeBelief; one without ``entropy`` or without a
    ``track_id`` fails the matching check."""
    assert isinstance(_Belief(), NodeBelief)
    assert not isinstance(_NoEntropy(), NodeBelief)
    assert not isinstance(_Belief(), TrackBelief)
    assert not isinstance(np.zeros(3), NodeBelief)


def test_the_estimators_satisfy_their_protocols(path3: RoadNetwork) -> None:
    """A node tracker is a TrackBelief, a bank a BeliefBank, the likelihood field a NodeBelief and
    SearchField (not a track), graph diffusion a SparseNodePredictor."""
    tracker = NodeTracker(np.array([0.2, 0.5, 0.3]), track_id=4)
    assert isinstance(tracker, TrackBelief) and isinstance(tracker, NodeBelief)
    bank = TrackerBank(3).with_birth(np.array([1.0, 0.0, 0.0]))
    assert isinstance(bank, BeliefBank) and isinstance(bank[0], TrackBelief)
    field = LikelihoodField.neutral(3)
    assert isinstance(field, SearchField) and isinstance(field, NodeBelief)
    assert not isinstance(field, TrackBelief)
    diffusion = GraphDiffusion.on_network(path3, 0.5, 1.0)
    assert isinstance(diffusion, SparseNodePredictor) and isinstance(diffusion, NodePredictor)
    assert not isinstance(tracker, NodePredictor)
