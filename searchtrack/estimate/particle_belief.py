"""The belief seam for planners in open space: a weighted particle set (a particle PHD).

A planner scoring actions on a particle belief (expected number of detections, mutual
information, exploration bonus) only reads positions and weights. The weights are PHD masses:
they sum to the expected number of targets ``λ``, not to 1 (paper 003, eq. 2 and §PHD Filter).
The SMC-PHD filter's :class:`~searchtrack.estimate.phd.PHDState` is one such belief;
:class:`WeightedParticles` is the plain one for callers holding raw arrays.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray


@runtime_checkable
class ParticleBelief(Protocol):
    """Particles ``{(x_i, w_i)}`` with ``v(x) ≈ Σ w_i δ(x − x_i)``."""

    @property
    def positions(self) -> NDArray[np.float64]:
        """``(N, p)`` particle positions (m), ``p`` = 2 or 3 (read-only)."""
        ...

    @property
    def weights(self) -> NDArray[np.float64]:
        """``(N,)`` non-negative masses summing to :meth:`expected_count` (read-only)."""
        ...

    def expected_count(self) -> float:
        """Expected number of targets ``λ = Σ w_i``."""
        ...


@dataclass(frozen=True, eq=False)
class WeightedParticles:
    """A particle belief from raw arrays: read-only copies, checked finite, ``w ≥ 0``.

    Parameters
    ----------
    positions
        ``(N, p)`` particle positions (m), ``p`` = 2 or 3.
    weights
        ``(N,)`` non-negative PHD masses.
    """

    positions: FloatArray
    weights: FloatArray

    def __post_init__(self) -> None:
        pos, w = checked_arrays(self.positions, self.weights)
        object.__setattr__(self, "positions", pos)
        object.__setattr__(self, "weights", w)

    def expected_count(self) -> float:
        """Expected number of targets ``λ = Σ w_i``."""
        return float(self.weights.sum())


def checked_arrays(positions: NDArray[np.floating], weights: NDArray[np.floating], *,
                   prefix: str = "") -> tuple[FloatArray, FloatArray]:
    """Read-only float copies of a belief's ``(N, 2|3)`` finite positions and ``(N,)`` finite
    non-negative weights; :class:`InvalidInputError` naming ``prefix + "positions"`` or
    ``prefix + "weights"`` otherwise."""
    pos = np.array(positions, dtype=np.float64, copy=True)
    if pos.ndim != 2 or pos.shape[1] not in (2, 3) or not np.all(np.isfinite(pos)):
        raise InvalidInputError(f"{prefix}positions", pos.shape,
                                "must be a finite (N, 2|3) array")
    w = np.array(weights, dtype=np.float64, copy=True)
    if w.shape != (pos.shape[0],) or not np.all(np.isfinite(w)) or np.any(w < 0.0):
        raise InvalidInputError(f"{prefix}weights", w.shape,
                                f"must be {pos.shape[0]} finite non-negative numbers")
    pos.setflags(write=False)
    w.setflags(write=False)
    return pos, w
