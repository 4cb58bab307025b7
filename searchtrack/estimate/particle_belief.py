"""The belief seam for planners in open space: a weighted particle set (a particle PHD).

A planner scoring actions on a particle belief (expected number of detections, mutual
information, exploration bonus) only reads positions and weights. The weights are PHD masses:
they sum to the expected number of targets ``λ``, not to 1 (paper 003, eq. 2 and §PHD Filter).
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray


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
