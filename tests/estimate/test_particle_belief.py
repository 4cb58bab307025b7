"""The particle belief seam: weighted particles from raw arrays, checked and read-only."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.particle_belief import ParticleBelief, WeightedParticles


def test_weighted_particles_are_a_particle_belief_with_count_the_weight_sum() -> None:
    """λ = Σ w (here 0.25 + 0.5 + 1.25 = 2); the class satisfies the protocol."""
    belief = WeightedParticles(np.zeros((3, 2)), np.array([0.25, 0.5, 1.25]))
    assert isinstance(belief, ParticleBelief)
    assert belief.expected_count() == 2.0
    assert WeightedParticles(np.zeros((0, 3)), np.zeros(0)).expected_count() == 0.0


def test_weighted_particles_copy_and_freeze_their_inputs() -> None:
    """The arrays are float copies nobody can write through; changing the caller's arrays
    afterwards changes nothing."""
    pos = np.array([[1, 2], [3, 4]])
    w = np.array([1.0, 2.0])
    belief = WeightedParticles(pos, w)
    pos[0, 0], w[0] = 99, 99.0
    assert belief.positions.dtype == np.float64 and belief.positions[0, 0] == 1.0
    assert belief.weights[0] == 1.0
    assert not belief.positions.flags.writeable and not belief.weights.flags.writeable


def test_three_dimensional_positions_are_accepted() -> None:
    """Positions may be (N, 3)."""
    assert WeightedParticles(np.ones((4, 3)), np.ones(4)).positions.shape == (4, 3)


@pytest.mark.parametrize(("positions", "weights", "field"), [
    (np.zeros((3, 4)), np.ones(3), "positions"),
    (np.zeros(3), np.ones(3), "positions"),
    (np.array([[0.0, math.nan]]), np.ones(1), "positions"),
    (np.zeros((3, 2)), np.ones(2), "weights"),
    (np.zeros((2, 2)), np.array([1.0, -0.5]), "weights"),
    (np.zeros((2, 2)), np.array([1.0, math.inf]), "weights"),
])
def test_bad_particles_name_the_field(positions: np.ndarray, weights: np.ndarray,
                                      field: str) -> None:
    """Wrong widths, non-finite positions, wrong lengths and negative or infinite weights
    raise InvalidInputError naming positions or weights."""
    with pytest.raises(InvalidInputError) as err:
        WeightedParticles(positions, weights)
    assert err.value.field == field


def test_protocol_needs_positions_weights_and_count() -> None:
    """An object without expected_count is not a ParticleBelief."""

    class _NoCount:
        positions = np.zeros((1, 2))
        weights = np.ones(1)

    assert not isinstance(_NoCount(), ParticleBelief)
