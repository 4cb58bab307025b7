"""The lattice of paper 004 (§4.1, Fig. 4): axis moves and the move sequences of one horizon."""

from __future__ import annotations

import itertools

import numpy as np

from searchtrack.core.checks import positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


def lattice_moves(step_m: float, dims: int = 3) -> FloatArray:
    """The ``2·dims`` axis moves ``±step_m`` of paper 004 (Fig. 4: six moves of 12 m in 3-D),
    ordered ``+x, +y(, +z), −x, −y(, −z)``."""
    positive("step_m", step_m)
    if dims not in (2, 3):
        raise InvalidInputError("dims", dims, "must be 2 or 3")
    eye = np.eye(3)[:dims]
    return np.concatenate([eye, -eye]) * step_m


def lattice_sequences(start: FloatArray, moves: FloatArray, horizon: int,
                      bounds: FloatArray) -> FloatArray:
    """``(S, horizon, 3)`` position sequences ``q_{k+1..k+τ}`` (004 eq. 7): every sequence of
    ``moves`` from ``start`` that stays inside ``bounds`` ``(3, 2)``, in lexicographic move
    order (``S ≤ |moves|^τ``)."""
    q0 = np.asarray(start, dtype=np.float64).reshape(-1)[:3]
    if not isinstance(horizon, int) or horizon < 1:
        raise InvalidInputError("horizon", horizon, "must be a positive integer")
    combos = np.array(list(itertools.product(range(moves.shape[0]), repeat=horizon)))
    steps = moves[combos]  # (S, τ, 3)
    seqs = q0 + np.cumsum(steps, axis=1)
    inside = np.all((seqs >= bounds[:, 0]) & (seqs <= bounds[:, 1]), axis=(1, 2))
    out: FloatArray = seqs[inside]
    return out
