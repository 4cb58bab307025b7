"""The road RBPF stepped by predict and update with its own generator."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import RoadParticleBelief
from searchtrack.estimate.road_rbpf import RBPFConfig, RoadRBPF
from searchtrack.estimate.road_rbpf_stepping import SteppedRoadRBPF
from searchtrack.estimate.stepping import SteppedFilter
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.road_synthetic import grid_network


def test_draws_what_the_bare_filter_draws() -> None:
    """Same generator seed, same calls: the same particles, entropies and MAP positions."""
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    config = RBPFConfig(n_targets=2, n_histories=4, n_particles=80)
    stepped = SteppedRoadRBPF(roads, config, np.random.default_rng(3))
    rng = np.random.default_rng(3)
    bare = RoadRBPF(roads, config, rng)
    assert isinstance(stepped, SteppedFilter) and isinstance(stepped, RoadParticleBelief)
    uav = np.array([100.0, 50.0])
    for k in range(12):
        ys = np.array([[100.0, 60.0]]) if k % 4 == 3 else np.empty((0, 2))
        stepped.predict(0.5)
        bare.predict(0.5, rng)
        stepped.update(ys, uav)
        bare.update(ys, uav, rng)
    for a, b in zip(stepped.target_particles(), bare.target_particles(), strict=True):
        assert np.array_equal(a, b)
    assert np.array_equal(stepped.target_entropy(), bare.target_entropy())
    assert stepped.combined_entropy() == bare.combined_entropy()
    assert stepped.summary()[1] == bare.summary()[1]
    assert stepped.n_targets == 2 and stepped.roads is roads


def test_bad_scans_and_generators_are_named() -> None:
    roads = DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))
    config = RBPFConfig(n_targets=1, n_histories=2, n_particles=20)
    with pytest.raises(InvalidInputError, match="rng"):
        SteppedRoadRBPF(roads, config, 7)  # type: ignore[arg-type]
    f = SteppedRoadRBPF(roads, config, np.random.default_rng(0))
    with pytest.raises(InvalidInputError, match="uav_xy"):
        f.update(np.empty((0, 2)), np.array([1.0, np.nan]))
