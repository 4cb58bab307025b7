"""The road filter bank with known association: each labelled detection updates its target, and
the bank fits every belief seam."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import BeliefBank, RoadParticleBelief, TrackBelief
from searchtrack.estimate.particle_belief import ParticleBelief
from searchtrack.estimate.road_filter_bank import RoadFilterBank
from searchtrack.models import grid_network
from searchtrack.models.road_particles import DirectedRoads

CENTRE = np.array([100.0, 100.0])


@pytest.fixture(scope="module")
def roads() -> DirectedRoads:
    """The paper's 3×3 map of 100 m roads."""
    return DirectedRoads(grid_network(3, 3, 100.0, spacing_m=100.0))


def test_bank_with_known_association(roads: DirectedRoads) -> None:
    """Each labelled detection updates its target; the bank fits every belief seam."""
    rng = np.random.default_rng(7)
    bank = RoadFilterBank(roads, 2, 400, rng)
    assert isinstance(bank, RoadParticleBelief)
    ys = np.array([[100.0, 40.0], [160.0, 200.0]])
    bank.update(ys, [1, -1], ys[0], rng)
    np.testing.assert_allclose(bank.map_positions()[1], ys[0], atol=5.0)
    h = bank.target_entropy()
    assert h.shape == (2,) and h[1] < h[0]
    edge, s, w = bank.target_particles()
    assert edge.shape == s.shape == w.shape == (2, 400)
    np.testing.assert_allclose(w.sum(axis=1), 1.0)
    beliefs = bank.node_beliefs()
    assert all(isinstance(b, TrackBelief) and b.mass() == 1.0 for b in beliefs)
    assert isinstance(bank.belief_bank(), BeliefBank) and len(bank.belief_bank()) == 2
    pb = bank.particle_belief()
    assert isinstance(pb, ParticleBelief) and pb.expected_count() == pytest.approx(2.0)
    assert h.mean() <= bank.combined_entropy() <= h.mean() + np.log(2) + 1e-12
    with pytest.raises(InvalidInputError, match="targets"):
        bank.update(ys, [0, 2], ys[0], rng)
    with pytest.raises(InvalidInputError, match="detections"):
        bank.update([[np.nan, 0.0]], [0], ys[0], rng)
