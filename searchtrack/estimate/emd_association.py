"""Gated EMD data association (thesis §4.3, Algorithm 1) and its optimal counterpart.

Both associators compute the EMD matrix ``DA`` between the trackers' priors and one UAV's
measurement densities (:func:`~searchtrack.estimate.emd_matrix.emd_matrix`: truncated signatures,
road distances in metres, pairs proven ≥ the gate skipped) and pair trackers with measurements
one-to-one, only where ``EMD < gate`` (``𝓔 = 300`` m in the thesis):

* :class:`GreedyEMDAssociator` is Algorithm 1: take the global minimum, remove its row and
  column, repeat while the minimum is below the gate.
* :class:`OptimalEMDAssociator` solves the gated assignment exactly: the one-to-one set of
  gated pairs minimising ``Σ (EMD − gate)``; greedy can only do worse or as well.

They satisfy the :class:`~searchtrack.estimate.association.Associator` protocol and are injected
into :class:`~searchtrack.estimate.scan.ScanUpdater`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike
from scipy.optimize import linear_sum_assignment

from searchtrack.core.deadline import check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.estimate.association import Association
from searchtrack.estimate.emd_matrix import (
    METHODS,
    check_gate,
    check_support_mass,
    checked_emd_matrix,
    distributions,
)
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.models.road_metric import RoadMetric
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.emd_association")

Pairs = tuple[tuple[int, int], ...]


def _cost_matrix(costs: ArrayLike) -> FloatArray:
    """``costs`` as a 2-D float array without NaN (``+inf`` allowed: never associable)."""
    try:
        c = np.array(costs, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise InvalidInputError("costs", costs, "must be a 2-D array of numbers") from None
    if c.ndim != 2:
        raise InvalidInputError("costs", costs, "must be a 2-D (trackers × measurements) array")
    if np.isnan(c).any():
        raise InvalidInputError("costs", costs, "must not contain NaN")
    return c


def greedy_pairs(costs: ArrayLike, gate_m: float) -> Pairs:
    """Algorithm 1's greedy gated matching on a ``(k, q)`` cost matrix, in the order chosen.

    Repeatedly take the smallest entry while it is ``< gate_m``, then remove its row and column.
    Ties go to the lowest tracker index, then the lowest measurement index.
    """
    c = _cost_matrix(costs)
    gate = check_gate(gate_m, inf_ok=False)
    pairs: list[tuple[int, int]] = []
    while c.size:
        i, j = divmod(int(np.argmin(c)), c.shape[1])  # first minimum in row-major order
        if not c[i, j] < gate:
            break
        pairs.append((i, j))
        c[i, :] = math.inf
        c[:, j] = math.inf
    return tuple(pairs)


def optimal_pairs(costs: ArrayLike, gate_m: float) -> Pairs:
    """The optimal gated assignment on a ``(k, q)`` cost matrix, sorted by tracker.

    Minimises ``Σ (c_ij − gate)`` over one-to-one sets of pairs with ``c_ij < gate``;
    equivalently every measurement either pairs with a tracker at cost ``c_ij`` or stays
    unassociated at cost ``gate``. As a linear assignment problem: pad the matrix with one
    "unassociated" dummy per measurement and per tracker at cost 0 after subtracting the gate;
    because a dummy is always free, this collapses to the rectangular problem on
    ``min(c − gate, 0)`` (an entry at 0 is a dummy in disguise and is dropped afterwards).
    The assignment LP has an integral optimum, which ``linear_sum_assignment`` finds exactly.
    """
    c = _cost_matrix(costs)
    gate = check_gate(gate_m, inf_ok=False)
    if c.size == 0:
        return ()
    rows, cols = linear_sum_assignment(np.minimum(c - gate, 0.0))
    keep = c[rows, cols] < gate
    return tuple(sorted(zip(rows[keep].tolist(), cols[keep].tolist(), strict=True)))


def gated_objective(costs: ArrayLike, pairs: Pairs, gate_m: float) -> float:
    """``Σ (c_ij − gate)`` over ``pairs``: the objective :func:`optimal_pairs` minimises."""
    c = _cost_matrix(costs)
    gate = check_gate(gate_m, inf_ok=False)
    return float(sum(c[i, j] - gate for i, j in pairs))


@dataclass(frozen=True, eq=False)
class _GatedEMD:
    """What both associators share: the EMD matrix with its gate, truncation and solver.

    Parameters
    ----------
    network
        The road network (a :class:`RoadMetric` of it is built once, on construction).
    gate_m
        The association gate ``𝓔`` (m): only pairs with EMD ``< gate_m`` may associate.
    support_mass
        Signature truncation, in ``(0, 1]`` (see :mod:`searchtrack.estimate.emd_matrix`).
    method
        ``"transport"`` (default, faster) or ``"graph"``: the exact EMD solver per pair.
    time_limit_s
        Wall-clock limit per call; pairs not solved in time count as unassociable (logged).
    """

    network: RoadNetwork
    gate_m: float = 300.0
    support_mass: float = 0.999
    method: str = "transport"
    time_limit_s: float = 1.0
    metric: RoadMetric = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        set_ = object.__setattr__
        set_(self, "gate_m", check_gate(self.gate_m, inf_ok=False))
        set_(self, "support_mass", check_support_mass(self.support_mass))
        if self.method not in METHODS:
            raise InvalidInputError("method", self.method, f"choose one of {list(METHODS)}")
        set_(self, "time_limit_s", check_time_limit(self.time_limit_s))
        set_(self, "metric", RoadMetric(self.network))

    def costs(self, bank: TrackerBank, densities: ArrayLike) -> FloatArray:
        """The ``(k, q)`` EMD matrix ``DA`` (m), ``+inf`` where a pair is proven ≥ the gate.

        Raises
        ------
        InvalidInputError
            ``bank`` not a :class:`TrackerBank` on the network's nodes, or ``densities`` not a
            ``(q, n)`` array of finite, non-negative rows with positive sums.
        """
        n = self.network.n_nodes
        if not isinstance(bank, TrackerBank) or bank.n_nodes != n:
            raise InvalidInputError("bank", bank, f"must be a TrackerBank on {n} nodes")
        dens = distributions("densities", densities, n)
        if not len(bank) or not dens.shape[0]:
            return np.full((len(bank), dens.shape[0]), math.inf)
        return checked_emd_matrix(self.metric, bank.probabilities(), dens, self.support_mass,
                                  self.gate_m, self.method, self.time_limit_s)

    def _pairs(self, costs: FloatArray) -> Pairs:
        raise NotImplementedError

    def associate_with_costs(
        self, bank: TrackerBank, densities: ArrayLike
    ) -> tuple[Association, FloatArray]:
        """The association and the EMD matrix it was chosen from (see :meth:`costs`)."""
        costs = self.costs(bank, densities)
        association = Association(self._pairs(costs))
        log.debug("%s: %d trackers x %d measurements -> pairs %s", type(self).__name__,
                  costs.shape[0], costs.shape[1], association.pairs)
        return association, costs

    def associate(self, bank: TrackerBank, densities: ArrayLike) -> Association:
        """Pair the rows of ``densities`` (``(q, n)`` measurement densities ``Û``) with the
        trackers of ``bank``; an empty bank or no measurement gives no pairs."""
        return self.associate_with_costs(bank, densities)[0]


@dataclass(frozen=True, eq=False)
class GreedyEMDAssociator(_GatedEMD):
    """Algorithm 1 (§4.3): greedy minimum-EMD pairs under the gate (:func:`greedy_pairs`)."""

    def _pairs(self, costs: FloatArray) -> Pairs:
        return greedy_pairs(costs, self.gate_m)


@dataclass(frozen=True, eq=False)
class OptimalEMDAssociator(_GatedEMD):
    """The optimal gated assignment: minimise ``Σ (EMD − gate)`` over one-to-one pairs with
    ``EMD < gate`` (:func:`optimal_pairs`); never worse than Algorithm 1 in that objective."""

    def _pairs(self, costs: FloatArray) -> Pairs:
        return optimal_pairs(costs, self.gate_m)
