"""The immutable state of the SMC-PHD filter: weighted particles plus what the last update saw.

``v(x) ≈ Σ w_i δ(x − x_i)`` (paper 003, §PHD Filter); the weights sum to the expected number of
targets. Each particle also carries a *label* (``NEWBORN`` if born in the last prediction) and a
*tag*: the group it was assigned to by the last update (the measurement that explains most of its
weight, or the missed target it belongs to; ``-1`` for none), which lets the next update
recognise a target that was missed. The :class:`UpdateRecord` keeps the per-measurement results of
the last update that extraction and the next birth need; a prediction clears it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray

PERSISTENT = 0
NEWBORN = 1
NO_TAG = -1


def _frozen(*arrays: NDArray[np.generic]) -> None:
    for arr in arrays:
        arr.setflags(write=False)


def _rows(name: str, arr: FloatArray, n: int, d: int) -> None:
    if arr.shape != (n, d):
        raise InvalidInputError(name, arr.shape, f"must have shape ({n}, {d})")


@dataclass(frozen=True)
class UpdateRecord:
    """Per-measurement results of the last update.

    Attributes
    ----------
    detection_states, detection_masses
        ``(k, d)`` weighted mean and ``(k,)`` mass ``ρ_z`` of each measurement's update term
        (``ρ_z = 0`` for a measurement over its target's one-estimate quota).
    missed_states, missed_existence
        ``(g, d)`` weighted mean and ``(g,)`` existence probability of each target of the
        previous scan that no measurement explained (see :mod:`searchtrack.estimate.phd.update`).
    seed_positions, seed_masses
        ``(k, p)`` birth seeds ``h⁻¹(z)`` and ``(k,)`` their birth masses.
    """

    detection_states: FloatArray
    detection_masses: FloatArray
    missed_states: FloatArray
    missed_existence: FloatArray
    seed_positions: FloatArray
    seed_masses: FloatArray

    def __post_init__(self) -> None:
        d = self.detection_states.shape[1] if self.detection_states.ndim == 2 else -1
        _rows("detection_states", self.detection_states, self.detection_masses.shape[0], d)
        _rows("missed_states", self.missed_states, self.missed_existence.shape[0], d)
        p = self.seed_positions.shape[1] if self.seed_positions.ndim == 2 else -1
        _rows("seed_positions", self.seed_positions, self.seed_masses.shape[0], p)
        _frozen(self.detection_states, self.detection_masses, self.missed_states,
                self.missed_existence, self.seed_positions, self.seed_masses)

    @classmethod
    def empty(cls, state_dim: int, position_dim: int) -> UpdateRecord:
        """No measurements, no missed targets, no seeds."""
        e = np.empty(0)
        return cls(np.empty((0, state_dim)), e, np.empty((0, state_dim)), e,
                   np.empty((0, position_dim)), e)


@dataclass(frozen=True)
class PHDState:
    """Weighted particles of a particle PHD and the record of the last update.

    Attributes
    ----------
    states
        ``(N, d)`` particle states; the first ``position_dim`` columns are the position (m).
    weights
        ``(N,)`` non-negative PHD masses.
    labels
        ``(N,)`` ``NEWBORN`` (1) for particles born in the last prediction, else ``PERSISTENT``.
    tags
        ``(N,)`` group of each particle in the last update (``NO_TAG`` = -1 for none).
    position_dim
        Number of position columns (2 or 3).
    record
        The last update's per-measurement results (empty after a prediction).
    """

    states: FloatArray
    weights: FloatArray
    labels: IntArray
    tags: IntArray
    position_dim: int
    record: UpdateRecord = field(repr=False)

    def __post_init__(self) -> None:
        n, d = self.states.shape if self.states.ndim == 2 else (-1, -1)
        if n < 0 or not 1 <= self.position_dim <= d:
            raise InvalidInputError("states", self.states.shape,
                                    f"must be (N, d) with d ≥ position_dim = {self.position_dim}")
        for name in ("weights", "labels", "tags"):
            if getattr(self, name).shape != (n,):
                raise InvalidInputError(name, getattr(self, name).shape, f"must be ({n},)")
        if self.record.detection_states.shape[1] != d or \
                self.record.seed_positions.shape[1] != self.position_dim:
            raise InvalidInputError("record", self.record.detection_states.shape,
                                    "must match the particles' dimensions")
        _frozen(self.states, self.weights, self.labels, self.tags)

    @classmethod
    def empty(cls, state_dim: int, position_dim: int = 2) -> PHDState:
        """A PHD with no particles (``λ = 0``)."""
        none = np.empty(0, dtype=np.int64)
        return cls(np.empty((0, state_dim)), np.empty(0), none, none.copy(), position_dim,
                   UpdateRecord.empty(state_dim, position_dim))

    @classmethod
    def from_particles(cls, states: FloatArray, weights: FloatArray,
                       position_dim: int = 2) -> PHDState:
        """A PHD of the given particles (``PERSISTENT``, untagged), checked finite and ``w ≥ 0``."""
        x = np.array(states, dtype=np.float64)
        w = np.array(weights, dtype=np.float64)
        if x.ndim != 2 or not np.all(np.isfinite(x)):
            raise InvalidInputError("states", states, "must be a finite (N, d) array")
        if w.shape != (x.shape[0],) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InvalidInputError("weights", weights,
                                    f"must be {x.shape[0]} finite non-negative numbers")
        n = x.shape[0]
        return cls(x, w, np.zeros(n, dtype=np.int64), np.full(n, NO_TAG, dtype=np.int64),
                   position_dim, UpdateRecord.empty(x.shape[1], position_dim))

    def select(self, index: NDArray[np.intp] | NDArray[np.int64] | NDArray[np.bool_],
               weights: FloatArray | None = None) -> PHDState:
        """The particles at ``index`` (a mask or indices), optionally with new weights; the
        record is kept."""
        w = self.weights[index] if weights is None else weights
        return PHDState(self.states[index], w, self.labels[index], self.tags[index],
                        self.position_dim, self.record)

    @property
    def n_particles(self) -> int:
        """Number of particles ``N``."""
        return int(self.weights.shape[0])

    @property
    def state_dim(self) -> int:
        """Length ``d`` of a state row."""
        return int(self.states.shape[1])

    @property
    def positions(self) -> FloatArray:
        """``(N, position_dim)`` particle positions (a read-only view)."""
        return self.states[:, : self.position_dim]

    def expected_count(self) -> float:
        """Expected number of targets ``λ = Σ w_i`` (paper 003, eq. 2; 004, eq. A7)."""
        return float(self.weights.sum())
