"""Trained road-search policies as NumPy networks."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError, ParseError
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.road_synthetic import grid_network
from searchtrack.plan.road_rl.features import RoadFeatures
from searchtrack.plan.road_rl.policy import RoadPolicy, policy_for


def _policy(n_in: int, n_out: int = 4, seed: int = 0, **kw: object) -> RoadPolicy:
    rng = np.random.default_rng(seed)
    w = (rng.normal(size=(8, n_in)), rng.normal(size=(n_out, 8)))
    b = (rng.normal(size=8), rng.normal(size=n_out))
    return RoadPolicy(w, b, **kw)  # type: ignore[arg-type]


def test_logits_are_the_dense_network() -> None:
    p = _policy(3)
    x = np.array([0.5, -1.0, 2.0])
    hidden = np.tanh(p.weights[0] @ x + p.biases[0])
    assert np.allclose(p.logits(x), p.weights[1] @ hidden + p.biases[1])
    assert p.act(x) == int(np.argmax(p.logits(x)))
    batch = np.stack([x, -x])
    assert p.logits(batch).shape == (2, 4)
    relu = _policy(3, activation="relu")
    assert np.allclose(relu.logits(x), relu.weights[1] @ np.maximum(
        relu.weights[0] @ x + relu.biases[0], 0) + relu.biases[1])


def test_save_and_load_round_trip(tmp_path: Path) -> None:
    p = _policy(5)
    p2 = RoadPolicy(p.weights, p.biases, "tanh", {"size": 5, "n_targets": 1})
    loaded = RoadPolicy.load(p2.save(tmp_path / "p.npz"))
    x = np.arange(5.0)
    assert np.allclose(loaded.logits(x), p.logits(x))
    assert loaded.signature == {"size": 5, "n_targets": 1}


def test_bad_files_are_parse_errors(tmp_path: Path) -> None:
    with pytest.raises(ParseError, match="no such"):
        RoadPolicy.load(tmp_path / "missing.npz")
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip")
    with pytest.raises(ParseError, match="not a policy"):
        RoadPolicy.load(junk)
    partial = tmp_path / "partial.npz"
    np.savez(partial, meta=np.array('{"layers": 2}'), w0=np.ones((2, 2)), b0=np.ones(2))
    with pytest.raises(ParseError, match="not a policy"):
        RoadPolicy.load(partial)


def test_bad_networks_are_refused() -> None:
    with pytest.raises(InvalidInputError, match="weights"):
        RoadPolicy((np.ones((2, 3)),), (np.ones(3),))
    with pytest.raises(InvalidInputError, match="weights"):
        RoadPolicy((np.ones((2, 3)), np.ones((4, 5))), (np.ones(2), np.ones(4)))
    with pytest.raises(InvalidInputError, match="activation"):
        _policy(3, activation="sigmoid")
    with pytest.raises(InvalidInputError, match="obs"):
        _policy(3).logits(np.ones(4))
    with pytest.raises(InvalidInputError, match="finite"):
        RoadPolicy((np.full((2, 3), np.nan),), (np.ones(2),))


def test_features_must_match_the_training_signature() -> None:
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    features = RoadFeatures(roads, 2)
    good = RoadPolicy(*_unpack(_policy(features.size)), "tanh", features.signature())
    assert policy_for(roads, good).size == features.size
    other = DirectedRoads(grid_network(2, 3, 100.0, spacing_m=100.0))
    with pytest.raises(InvalidInputError, match="other features"):
        policy_for(other, good)
    unsigned = _policy(7)
    with pytest.raises(InvalidInputError, match="takes 7 features"):
        unsigned.check_features(features)


def test_choose_takes_the_action_modulo_the_degree() -> None:
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    features = RoadFeatures(roads, 1)
    n_actions = 7

    class _B:
        roads = None
        n_targets = 1

        def target_particles(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
            return np.zeros((1, 2), dtype=np.int64), np.zeros((1, 2)), np.full((1, 2), 0.5)

        def target_entropy(self) -> np.ndarray:
            return np.ones(1)

    w = (np.zeros((n_actions, features.size)),)
    b = (np.eye(n_actions)[6],)  # always action 6
    p = RoadPolicy(w, b)
    leaving = np.array([10, 11, 12])
    assert p.choose(features, _B(), np.zeros((1, 2)), 0, leaving) == 10  # 6 mod 3 = 0
    with pytest.raises(InvalidInputError, match="no road"):
        p.choose(features, _B(), np.zeros((1, 2)), 0, np.zeros(0, dtype=np.int64))


def _unpack(p: RoadPolicy) -> tuple[tuple[np.ndarray, ...], tuple[np.ndarray, ...]]:
    return p.weights, p.biases
