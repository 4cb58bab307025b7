"""The belief seam between estimation and planning: what a planner may ask of a belief on nodes.

Planners score candidate actions with a reward that takes a belief (the Stone Soup sensor-manager
seam). Every estimate in this package — the likelihood-ratio field, one node tracker, a bank of
trackers — satisfies :class:`NodeBelief`, so a reward can be written once against it.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray


@runtime_checkable
class NodeBelief(Protocol):
    """A non-negative mass over the ``n`` nodes of a road network.

    ``node_probability()`` sums to ``mass()``: 1 for one target's location, the number of
    trackers for a bank of them, 0 for an empty bank. ``entropy()`` and ``peak_node()`` refer to
    the normalized distribution ``node_probability() / mass()``.
    """

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n``."""
        ...

    def node_probability(self) -> NDArray[np.float64]:
        """``(n,)`` non-negative mass on each node (a new array the caller may change)."""
        ...

    def mass(self) -> float:
        """Total mass ``node_probability().sum()``."""
        ...

    def peak_node(self) -> int:
        """Index of the node of highest mass (the lowest such index on ties)."""
        ...

    def entropy(self) -> float:
        """Shannon entropy (nats) of the normalized distribution; 0 when the mass is 0."""
        ...


def entropy_nats(probability: NDArray[np.float64]) -> float:
    """Shannon entropy ``−Σ p log p`` (nats) of ``probability / probability.sum()``, 0 if empty.

    Zero entries contribute nothing (``0 log 0 = 0``); a uniform distribution on ``n`` nodes has
    entropy ``log n``.
    """
    total = float(probability.sum())
    if total <= 0.0:
        return 0.0
    p = probability[probability > 0.0] / total
    return float(-(p * np.log(p)).sum())
