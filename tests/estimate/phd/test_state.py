"""The SMC-PHD state: weighted particles with labels, tags and the last update's record."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.particle_belief import ParticleBelief
from searchtrack.estimate.phd import PERSISTENT, PHDState
from searchtrack.estimate.phd.state import NO_TAG, UpdateRecord

from .helpers import cloud as _cloud
from .helpers import phd_state as _state


def test_state_is_a_particle_belief() -> None:
    """PHDState satisfies the ParticleBelief protocol; weights sum to the expected count."""
    st = _state(_cloud((100, 100), 50, 2.0))
    assert isinstance(st, ParticleBelief)
    assert st.expected_count() == pytest.approx(2.0)
    assert st.positions.shape == (50, 2)


def test_empty_state_has_no_mass() -> None:
    """An empty PHD has no particles, λ = 0 and an empty record of the right widths."""
    st = PHDState.empty(4, position_dim=3)
    assert (st.n_particles, st.state_dim, st.position_dim) == (0, 4, 3)
    assert st.expected_count() == 0.0 and st.positions.shape == (0, 3)
    assert st.record.detection_states.shape == (0, 4) and st.record.seed_positions.shape == (0, 3)


def test_from_particles_is_persistent_untagged_and_read_only() -> None:
    """Particles from arrays are PERSISTENT and untagged; every array is frozen and a copy."""
    x = np.array([[1.0, 2.0, 0.5, 0.0], [3.0, 4.0, 0.0, 0.5]])
    w = np.array([0.25, 0.75])
    st = PHDState.from_particles(x, w)
    x[0, 0] = 99.0
    assert st.states[0, 0] == 1.0
    assert st.labels.tolist() == [PERSISTENT, PERSISTENT] and st.tags.tolist() == [NO_TAG] * 2
    np.testing.assert_array_equal(st.positions, [[1.0, 2.0], [3.0, 4.0]])
    for arr in (st.states, st.weights, st.labels, st.tags):
        assert not arr.flags.writeable


def test_select_keeps_the_record_and_may_reweight() -> None:
    """select() takes particles by mask or index, with their weights or new ones."""
    st = PHDState.from_particles(np.arange(6.0).reshape(3, 2), np.array([1.0, 2.0, 3.0]))
    by_mask = st.select(np.array([True, False, True]))
    assert by_mask.weights.tolist() == [1.0, 3.0] and by_mask.record is st.record
    by_index = st.select(np.array([2, 2]), np.array([0.5, 0.5]))
    np.testing.assert_array_equal(by_index.states, [[4.0, 5.0], [4.0, 5.0]])
    assert by_index.expected_count() == 1.0


def test_bad_states_name_the_field() -> None:
    """Non-finite or 1-D states, weights of the wrong length, a position wider than the state,
    and a record of other dimensions are refused naming the field."""
    with pytest.raises(InvalidInputError, match="states"):
        PHDState.from_particles(np.array([[0.0, np.inf]]), np.ones(1))
    with pytest.raises(InvalidInputError, match="states"):
        PHDState.from_particles(np.zeros(3), np.ones(3))
    with pytest.raises(InvalidInputError, match="weights"):
        PHDState.from_particles(np.zeros((3, 2)), np.ones(2))
    with pytest.raises(InvalidInputError, match="states"):
        PHDState.from_particles(np.zeros((3, 2)), np.ones(3), position_dim=3)
    with pytest.raises(InvalidInputError, match="record"):
        PHDState(np.zeros((1, 4)), np.ones(1), np.zeros(1, dtype=np.int64),
                 np.zeros(1, dtype=np.int64), 2, UpdateRecord.empty(2, 2))


@pytest.mark.parametrize(("field", "change"), [
    ("detection_states", {"detection_states": np.zeros((2, 4))}),
    ("missed_states", {"missed_states": np.zeros((1, 3))}),
    ("seed_positions", {"seed_positions": np.zeros((2, 2))}),
])
def test_update_record_rows_must_match(field: str, change: dict[str, np.ndarray]) -> None:
    """Each of the record's state arrays has one row per mass and the same width."""
    args = {"detection_states": np.zeros((1, 4)), "detection_masses": np.ones(1),
            "missed_states": np.zeros((1, 4)), "missed_existence": np.ones(1),
            "seed_positions": np.zeros((1, 2)), "seed_masses": np.ones(1), **change}
    with pytest.raises(InvalidInputError) as err:
        UpdateRecord(**args)
    assert err.value.field == field
