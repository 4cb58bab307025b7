"""The move lattice of paper 004 (eq. 7, Fig. 4): the axis moves and the in-box sequences."""

from __future__ import annotations

import numpy as np
import pytest

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.search import lattice_moves, lattice_sequences


def test_lattice_moves_and_sequences() -> None:
    """Six axis moves; sequences leaving the box are dropped; count is 6^τ inside."""
    moves = lattice_moves(12.0)
    assert moves.shape == (6, 3)
    assert np.allclose(np.linalg.norm(moves, axis=1), 12.0)
    box = np.array([[-100.0, 100.0]] * 3)
    assert lattice_sequences(np.zeros(3), moves, 2, box).shape == (36, 2, 3)
    corner = np.array([[0.0, 100.0]] * 3)
    seqs = lattice_sequences(np.zeros(3), moves, 1, corner)
    assert seqs.shape == (3, 1, 3)
    with pytest.raises(InvalidInputError, match="step_m"):
        lattice_moves(-1.0)


def test_move_order() -> None:
    """Moves are ordered +x, +y(, +z), −x, −y(, −z); the four planar moves do not climb."""
    planar = lattice_moves(2.0, dims=2)
    assert planar.shape[0] == 4
    np.testing.assert_array_equal(planar[:, :2], [[2.0, 0.0], [0.0, 2.0], [-2.0, 0.0],
                                                  [0.0, -2.0]])
    assert np.all(planar[:, 2:] == 0.0)
    np.testing.assert_array_equal(lattice_moves(1.0)[[2, 5]], [[0.0, 0.0, 1.0],
                                                               [0.0, 0.0, -1.0]])


def test_sequences_are_cumulative_and_lexicographic() -> None:
    """Sequences are running sums of the moves, in lexicographic move order: (+x, +x) first,
    then (+x, +y), ..., (−z, −z) last."""
    box = np.array([[-100.0, 100.0]] * 3)
    seqs = lattice_sequences(np.array([1.0, 2.0, 3.0]), lattice_moves(12.0), 2, box)
    np.testing.assert_array_equal(seqs[0], [[13.0, 2.0, 3.0], [25.0, 2.0, 3.0]])
    np.testing.assert_array_equal(seqs[1], [[13.0, 2.0, 3.0], [13.0, 14.0, 3.0]])
    np.testing.assert_array_equal(seqs[-1], [[1.0, 2.0, -9.0], [1.0, 2.0, -21.0]])


def test_box_bounds_are_inclusive_at_every_step() -> None:
    """In a box one move wide from its corner: three first moves, each followed by three that
    stay in (back, or along one of the two other axes): nine sequences."""
    box = np.array([[0.0, 12.0]] * 3)
    seqs = lattice_sequences(np.zeros(3), lattice_moves(12.0), 2, box)
    assert seqs.shape == (9, 2, 3)
    assert np.all((seqs >= 0.0) & (seqs <= 12.0))


def test_lattice_bad_input() -> None:
    """Bad dimensions and horizons raise naming the field."""
    with pytest.raises(InvalidInputError, match="dims"):
        lattice_moves(1.0, dims=4)
    with pytest.raises(InvalidInputError, match="step_m"):
        lattice_moves(np.nan)
    with pytest.raises(InvalidInputError, match="horizon"):
        lattice_sequences(np.zeros(3), lattice_moves(1.0), 0, np.array([[-1.0, 1.0]] * 3))
