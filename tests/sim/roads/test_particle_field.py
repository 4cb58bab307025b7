"""The particle search field: scores that follow the untracked mass, the SearchField protocol,
and bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import SearchField
from searchtrack.models import RoadNetwork, grid_network
from searchtrack.sim.roads.particle_field import (
    SCORE_FLOOR,
    ParticleFieldBuilder,
    ParticleSearchField,
)


@pytest.fixture(scope="module")
def network() -> RoadNetwork:
    """A 4 × 4 grid of 100 m blocks, nodes every 10 m."""
    return grid_network(4, 4, 100.0, 10.0)


def test_field_scores_follow_the_mass(network: RoadNetwork) -> None:
    """The uniform prior scores 0 everywhere; mass piled on one node scores above the prior
    there and the floor far from it; no target leaves the field neutral."""
    builder = ParticleFieldBuilder(network, 50.0)
    share = np.zeros(network.n_nodes)
    np.add.at(share, network.edges.ravel(), np.repeat(0.5 * network.lengths_m, 2))
    uniform = builder.field(2.0 * share / share.sum(), 2)
    np.testing.assert_allclose(uniform.node_score(), 0.0, atol=1e-9)
    piled = np.zeros(network.n_nodes)
    v = int(network.nearest_nodes(np.array([[150.0, 100.0]]))[0])
    piled[v] = 1.0
    score = builder.field(piled, 1).node_score()
    far = int(network.nearest_nodes(np.array([[300.0, 300.0]]))[0])
    assert score[v] > 0.0 and np.count_nonzero(score > SCORE_FLOOR) < network.n_nodes / 2
    assert score[far] == SCORE_FLOOR
    assert np.all(np.isfinite(score))
    np.testing.assert_array_equal(builder.field(piled, 0).node_score(), 0.0)


def test_field_is_a_search_field_and_read_only(network: RoadNetwork) -> None:
    """The adapter satisfies the SearchField protocol, cannot be written through, and turns
    into a LikelihoodField for the log."""
    field = ParticleFieldBuilder(network, 50.0).field(np.ones(network.n_nodes), 1)
    assert isinstance(field, SearchField)
    assert field.n_nodes == network.n_nodes
    with pytest.raises(ValueError, match="read-only"):
        field.node_score()[0] = 1.0


@pytest.mark.parametrize(("make", "name"), [
    (lambda net: ParticleFieldBuilder(net, 0.0), "radius_m"),
    (lambda net: ParticleFieldBuilder(net, math.inf), "radius_m"),
    (lambda net: ParticleFieldBuilder(net, 50.0, floor=0.0), "floor"),
    (lambda net: ParticleSearchField(np.array([0.0, math.nan])), "score"),
    (lambda net: ParticleSearchField(np.zeros((2, 2))), "score"),
])
def test_bad_inputs_name_the_field(network: RoadNetwork, make: object, name: str) -> None:
    """Bad radii, floors and scores are refused by name."""
    with pytest.raises(InvalidInputError) as info:
        make(network)  # type: ignore[operator]
    assert info.value.field == name
