"""Gated EMD data association (thesis §4.3, Algorithm 1) and its optimal counterpart.

:class:`EMDAssociator` computes the EMD matrix ``DA`` between the trackers' priors and one UAV's
measurement densities (:func:`~searchtrack.estimate.emd_matrix.emd_matrix`: truncated signatures,
road distances in metres, pairs proven ≥ the gate skipped), then pairs trackers with measurements
one-to-one, only where ``EMD < gate`` (``𝓔 = 300`` m in the thesis), with a backend of
:data:`searchtrack.estimate.association.BACKENDS` chosen by name:

* ``"greedy"`` is Algorithm 1: take the global minimum, remove its row and column, repeat while
  the minimum is below the gate.
* ``"optimal"`` solves the gated assignment exactly: the one-to-one set of gated pairs
  minimising ``Σ (EMD − gate)``; greedy can only do worse or as well.
* ``"auto"``: greedy, then the exact assignment in the time left.

It satisfies the :class:`~searchtrack.estimate.association.Associator` protocol and is injected
into :class:`~searchtrack.estimate.scan.ScanUpdater`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.deadline import Deadline, check_time_limit
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.result import Result
from searchtrack.core.types import FloatArray
from searchtrack.estimate.association import (
    BACKENDS,
    Association,
    AssociationProblem,
    solve,
)
from searchtrack.estimate.emd_matrix import METHODS, checked_emd_matrix
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.estimate.signatures import check_gate, check_support_mass, distributions
from searchtrack.models.road_metric import RoadMetric
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.emd_association")


@dataclass(frozen=True, eq=False)
class EMDAssociator:
    """Associate by EMD under the gate, pairing with a named backend (Algorithm 1 by default).

    Parameters
    ----------
    network
        The road network (a :class:`RoadMetric` of it is built once, on construction).
    backend
        How trackers and measurements are paired on the EMD matrix: a name of
        :data:`searchtrack.estimate.association.BACKENDS` (``"greedy"``, ``"optimal"``,
        ``"auto"``).
    gate_m
        The association gate ``𝓔`` (m): only pairs with EMD ``< gate_m`` may associate.
    support_mass
        Signature truncation, in ``(0, 1]`` (see :mod:`searchtrack.estimate.emd_matrix`).
    method
        The exact EMD solver per pair, a name of
        :data:`~searchtrack.estimate.emd_matrix.METHODS` (``"transport"``, the default and the
        faster, or ``"graph"``).
    time_limit_s
        Wall-clock limit per call; pairs not solved in time count as unassociable (logged).
    """

    network: RoadNetwork
    backend: str = "greedy"
    gate_m: float = 300.0
    support_mass: float = 0.999
    method: str = "transport"
    time_limit_s: float = 1.0
    metric: RoadMetric = field(init=False, repr=False)

    def __post_init__(self) -> None:
        if not isinstance(self.network, RoadNetwork):
            raise InvalidInputError("network", self.network, "must be a RoadNetwork")
        BACKENDS.get(self.backend)  # raises, listing the names, when unknown
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
        return self._costs(bank, densities, self.time_limit_s)

    def _costs(self, bank: TrackerBank, densities: ArrayLike, time_limit_s: float) -> FloatArray:
        n = self.network.n_nodes
        if not isinstance(bank, TrackerBank) or bank.n_nodes != n:
            raise InvalidInputError("bank", bank, f"must be a TrackerBank on {n} nodes")
        dens = distributions("densities", densities, n)
        if not len(bank) or not dens.shape[0]:
            return np.full((len(bank), dens.shape[0]), math.inf)
        return checked_emd_matrix(self.metric, bank.probabilities(), dens, self.support_mass,
                                  self.gate_m, self.method, time_limit_s)

    def solve_with_costs(
        self, bank: TrackerBank, densities: ArrayLike
    ) -> tuple[Result[Association], FloatArray]:
        """The pairing backend's result and the EMD matrix it was solved on (see
        :meth:`costs`); the EMD matrix and the pairing share :attr:`time_limit_s`."""
        deadline = Deadline(self.time_limit_s)
        costs = self._costs(bank, densities, self.time_limit_s)
        result = solve(AssociationProblem(costs, self.gate_m), backend=self.backend,
                       time_limit_s=max(1e-3, deadline.remaining()))
        log.debug("%s: %d trackers x %d measurements -> %s pairs %s", self.backend,
                  costs.shape[0], costs.shape[1], result.status.name,
                  result.plan.pairs if result.plan is not None else None)
        return result, costs

    def associate_with_costs(
        self, bank: TrackerBank, densities: ArrayLike
    ) -> tuple[Association, FloatArray]:
        """The association and the EMD matrix it was chosen from (see :meth:`costs`); no pairs
        when the backend answers without a plan (logged)."""
        result, costs = self.solve_with_costs(bank, densities)
        if result.plan is None:
            log.warning("association %s gave no plan (%s: %s); nothing associated",
                        self.backend, result.status.name, result.message)
            return Association(), costs
        return result.plan, costs

    def associate(self, bank: TrackerBank, densities: ArrayLike) -> Association:
        """Pair the rows of ``densities`` (``(q, n)`` measurement densities ``Û``) with the
        trackers of ``bank``; an empty bank or no measurement gives no pairs."""
        return self.associate_with_costs(bank, densities)[0]
