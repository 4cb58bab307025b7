"""The association seam: which tracker, if any, each position measurement belongs to.

estimate/ defines the protocol; the associators themselves (the thesis's greedy gated EMD,
Algorithm 1, and an optimal assignment) live in ``searchtrack.plan`` and are injected into
:class:`~searchtrack.estimate.scan.ScanUpdater`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.node_tracker import TrackerBank


@dataclass(frozen=True)
class Association:
    """One-to-one pairs ``(tracker index, measurement index)``; the rest go unassociated.

    Indices refer to the bank's tracker order and the rows of the measurement densities.
    """

    pairs: tuple[tuple[int, int], ...] = ()

    def __post_init__(self) -> None:
        pairs = tuple((int(t), int(q)) for t, q in self.pairs)
        trackers = [t for t, _ in pairs]
        measurements = [q for _, q in pairs]
        if len(set(trackers)) != len(trackers) or len(set(measurements)) != len(measurements):
            raise InvalidInputError("pairs", self.pairs, "use each tracker and measurement once")
        if any(i < 0 for i in trackers + measurements):
            raise InvalidInputError("pairs", self.pairs, "indices must be ≥ 0")
        object.__setattr__(self, "pairs", pairs)

    def unassociated(self, n_measurements: int) -> tuple[int, ...]:
        """Indices in ``range(n_measurements)`` that no tracker took."""
        taken = {q for _, q in self.pairs}
        return tuple(q for q in range(n_measurements) if q not in taken)


class Associator(Protocol):
    """Pair measurements of one UAV's scan with trackers (Algorithm 1, lines 4–14)."""

    def associate(self, bank: TrackerBank, densities: NDArray[np.float64]) -> Association:
        """Associate the rows of ``densities`` — ``(q, n)`` normalized measurement densities
        ``Û_k^j`` (§4.3) — with the trackers of ``bank`` (at least one of each)."""
        ...
