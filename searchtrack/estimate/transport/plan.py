"""What an EMD solve returns: a sparse transport plan, or a flow on the arcs of a graph."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.types import FloatArray, IntArray


def _frozen(*arrays: NDArray[np.generic]) -> None:
    for a in arrays:
        a.setflags(write=False)


@dataclass(frozen=True, eq=False)
class TransportPlan:
    """The flow ``f_ig`` of the transportation LP (4.3)–(4.7), stored sparsely.

    Parameters
    ----------
    rows, cols, amounts
        ``amounts[k] > 0`` units of mass move from ``p[rows[k]]`` to ``q[cols[k]]``. An optimal
        basic plan has at most ``m + n − 1`` entries.
    shape
        ``(m, n)``, the lengths of ``p`` and ``q``.
    work
        ``Σ d_ig f_ig``, the objective (4.3).
    total_flow
        ``Σ f_ig`` (4.7): 1 for normalised signatures, ``min(Σp, Σq)`` for partial EMD.
    """

    rows: IntArray
    cols: IntArray
    amounts: FloatArray
    shape: tuple[int, int]
    work: float
    total_flow: float

    def __post_init__(self) -> None:
        _frozen(self.rows, self.cols, self.amounts)

    @property
    def emd(self) -> float:
        """Earth Mover's Distance ``work / total_flow`` (Rubner et al.; thesis below (4.7))."""
        return self.work / self.total_flow

    def dense(self) -> FloatArray:
        """The ``(m, n)`` flow matrix."""
        flow = np.zeros(self.shape, dtype=np.float64)
        flow[self.rows, self.cols] = self.amounts
        return flow


@dataclass(frozen=True, eq=False)
class GraphFlow:
    """A min-cost flow on the arcs of a graph whose cost is the EMD under the path metric.

    Parameters
    ----------
    tails, heads, amounts
        ``amounts[k] > 0`` units of mass travel along the arc ``tails[k] → heads[k]``.
    n_nodes
        Number of graph nodes.
    work
        ``Σ ℓ_e f_e``: the arc lengths times the flows.
    total_flow
        Mass moved from ``p`` to ``q``: 1 when normalised, ``min(Σp, Σq)`` for partial EMD.
    """

    tails: IntArray
    heads: IntArray
    amounts: FloatArray
    n_nodes: int
    work: float
    total_flow: float

    def __post_init__(self) -> None:
        _frozen(self.tails, self.heads, self.amounts)

    @property
    def emd(self) -> float:
        """Earth Mover's Distance ``work / total_flow``."""
        return self.work / self.total_flow

    def net_outflow(self) -> FloatArray:
        """Outflow minus inflow at every node (``p − q`` for balanced masses)."""
        out = np.bincount(self.tails, weights=self.amounts, minlength=self.n_nodes)
        into = np.bincount(self.heads, weights=self.amounts, minlength=self.n_nodes)
        return np.asarray(out - into, dtype=np.float64)
