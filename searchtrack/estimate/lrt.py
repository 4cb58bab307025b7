"""The log-likelihood-ratio tracker (LRT) on the road graph (thesis 001, Ch. 3 and §4.1).

The state is a :class:`LikelihoodField`: the log-likelihood ratio ``φ`` of "a target is here"
against "no target is here" on every node, starting neutral (``φ = 0``). Roles:
:class:`LRTPredictor` (diffusion with decay, (3.8)), :func:`update_likelihood_field` (the disc
update ``m(ζ − m/2)``, §3.3) and :class:`LRTInitiator` (detection at ``φ_max``, tracker birth
from each connected super-threshold component, and suppression of those nodes to 0, §4.1).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import csgraph

from searchtrack.core.checks import node_set, node_vector, positive, real
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import entropy_nats
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.estimate.node_tracker import TrackerBank
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.lrt")

BirthWeighting = Literal["llr", "likelihood_ratio"]


@dataclass(frozen=True, eq=False)
class LikelihoodField:
    """The LRT state ``φ ∈ ℝⁿ``, the log-likelihood ratio (3.3) on each node; a
    :class:`~searchtrack.estimate.belief.NodeBelief` and a
    :class:`~searchtrack.estimate.belief.SearchField`.

    As a belief it is the location of one undetected target under a uniform prior: since
    ``φ(v)`` is the log ratio of the data's likelihood with the target at ``v`` to that with no
    target, ``node_probability() ∝ exp(φ)`` (a softmax), with mass 1. As a search field its
    :meth:`node_score` is ``φ`` itself, the surface the gradient force (5.6)–(5.7) climbs.
    """

    llr: NDArray[np.float64]

    def __post_init__(self) -> None:
        object.__setattr__(self, "llr", node_vector("llr", self.llr))

    @classmethod
    def neutral(cls, n_nodes: int) -> LikelihoodField:
        """The initial field ``φ = 0`` everywhere: neither likely nor unlikely."""
        if isinstance(n_nodes, bool) or not isinstance(n_nodes, (int, np.integer)) or n_nodes < 1:
            raise InvalidInputError("n_nodes", n_nodes, "must be an integer ≥ 1")
        return cls(np.zeros(int(n_nodes)))

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n``."""
        return int(self.llr.size)

    def node_score(self) -> NDArray[np.float64]:
        """``φ`` (read-only, not a copy): the search score of the gradient force (5.6)."""
        return self.llr

    def node_probability(self) -> NDArray[np.float64]:
        """``exp(φ) / Σ exp(φ)``, computed without overflow."""
        w = np.exp(self.llr - self.llr.max())
        return np.asarray(w / w.sum(), dtype=np.float64)

    def mass(self) -> float:
        """Always 1 (one undetected target's location)."""
        return 1.0

    def peak_node(self) -> int:
        """Node of highest ``φ`` (lowest index on ties)."""
        return int(np.argmax(self.llr))

    def entropy(self) -> float:
        """Entropy (nats) of the softmax; ``log n`` for the neutral field."""
        return entropy_nats(self.node_probability())


def llr_increment(zeta: float, sensitivity: float) -> float:
    """``log 𝓛(ζ|ξ) = m(ζ − m/2)`` (§3.3, from (3.3), (3.10), (3.11)) for a measurement ``ζ``."""
    z = real("zeta", zeta)
    m = positive("sensitivity", sensitivity)
    return m * (z - 0.5 * m)


def update_likelihood_field(
    field: LikelihoodField, zeta: float | ArrayLike, footprint: ArrayLike, sensitivity: float,
    floor: float = -math.inf,
) -> LikelihoodField:
    """Add ``m(ζ − m/2)`` to ``φ`` on every node of the sensor footprint (§3.3).

    A target seen (``ζ`` near ``m``) raises the disc by about ``m²/2``; nothing seen (``ζ`` near
    0) lowers it by as much. Several UAVs are assimilated by consecutive calls (§3.1).

    Parameters
    ----------
    zeta
        The measurement ``ζ`` in standard-deviation units: one scalar for the whole footprint
        (the thesis), or one value per footprint node (localised evidence).
    footprint
        Indices of the nodes within the footprint radius ``ρ`` of the UAV (may be empty).
    sensitivity
        ``m = z(P_d) − z(P_f) > 0`` (3.9).
    floor
        Lowest value ``φ`` may take on the updated nodes (``−inf``: none, the thesis). Negative
        information otherwise piles up without bound where the UAVs fly often (hundreds of
        nats), and a target that later drives there is buried: its ``+m²/2`` per step is
        averaged away by its deeply negative neighbours before ``φ`` can reach ``φ_max``.
    """
    nodes = node_set("footprint", footprint, field.n_nodes)
    inc = zeta_increments(zeta, nodes.size, sensitivity)
    if math.isnan(floor):
        raise InvalidInputError("floor", floor, "must be a number or -inf")
    llr = np.array(field.llr, copy=True)
    np.add.at(llr, nodes, inc)
    if floor > -math.inf and nodes.size:
        llr[nodes] = np.maximum(llr[nodes], floor)
    return LikelihoodField(llr)


def zeta_increments(zeta: float | ArrayLike, n_nodes: int,
                    sensitivity: float) -> float | NDArray[np.float64]:
    """``m(ζ − m/2)`` for a scalar ``ζ``, or per node for an ``(n_nodes,)`` array of them."""
    if np.ndim(zeta) == 0:
        return llr_increment(float(zeta), sensitivity)  # type: ignore[arg-type]
    z = np.asarray(zeta, dtype=np.float64)
    if z.shape != (n_nodes,) or not np.all(np.isfinite(z)):
        raise InvalidInputError("zeta", zeta, f"must be a finite scalar or ({n_nodes},) array, "
                                "one value per footprint node")
    m = positive("sensitivity", sensitivity)
    return np.asarray(m * (z - 0.5 * m), dtype=np.float64)


@dataclass(frozen=True, eq=False)
class LRTPredictor:
    """``φ_k = e^{−α(L + I/C)Δt} φ_{k−1}`` (3.8): spread at rate ``α``, decay to 0 at ``α/C``."""

    diffusion: GraphDiffusion

    def predict(self, field: LikelihoodField) -> LikelihoodField:
        """The field one step ``Δt`` later, without measurements."""
        if field.n_nodes != self.diffusion.n_nodes:
            raise InvalidInputError("field", field.n_nodes,
                                    f"must be on {self.diffusion.n_nodes} nodes")
        return LikelihoodField(self.diffusion.propagate(field.llr))


@dataclass(frozen=True, eq=False)
class LRTInitiator:
    """Detect at ``φ ≥ φ_max`` and turn each connected super-threshold component into a tracker.

    Per §4.1: the tracker is formed from the component's nodes and their likelihood,
    normalized to one, and those nodes of the LRT are suppressed to zero (neutral). Every
    component becomes its own tracker, highest peak first.

    Parameters
    ----------
    network
        The road network (its adjacency decides which super-threshold nodes are connected).
    threshold
        ``φ_max`` (10 in Tables 6.2 and 6.4), > 0.
    weighting
        ``"llr"`` (the thesis read literally: probabilities ∝ ``φ`` on the component) or
        ``"likelihood_ratio"`` (∝ ``exp φ``, which peaks more sharply; §4.1's "their
        likelihood" reads either way).
    merge_radius_m
        A component whose peak node lies within this distance of an existing tracker's peak is
        suppressed without a birth: its evidence is the tracked target's (the thesis has no such
        rule; 0, the default, births every component).
    """

    network: RoadNetwork
    threshold: float = 10.0
    weighting: BirthWeighting = "llr"
    merge_radius_m: float = 0.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "threshold", positive("threshold", self.threshold))
        radius = real("merge_radius_m", self.merge_radius_m)
        if radius < 0.0:
            raise InvalidInputError("merge_radius_m", self.merge_radius_m, "must be ≥ 0 (m)")
        object.__setattr__(self, "merge_radius_m", radius)
        if self.weighting not in ("llr", "likelihood_ratio"):
            raise InvalidInputError("weighting", self.weighting,
                                    "must be 'llr' or 'likelihood_ratio'")

    def initiate(
        self, field: LikelihoodField, bank: TrackerBank
    ) -> tuple[LikelihoodField, TrackerBank]:
        """The suppressed field and the bank with one new tracker per detection (none if
        ``max φ < φ_max``)."""
        n = self.network.n_nodes
        if field.n_nodes != n or bank.n_nodes != n:
            raise InvalidInputError("field", (field.n_nodes, bank.n_nodes),
                                    f"field and bank must be on the network's {n} nodes")
        hot = np.flatnonzero(field.llr >= self.threshold)
        if hot.size == 0:
            return field, bank
        sub = self.network.adjacency[hot][:, hot]
        count, labels = csgraph.connected_components(sub, directed=False)
        phi = field.llr[hot]
        peaks = [float(phi[labels == c].max()) for c in range(count)]
        llr = np.array(field.llr, copy=True)
        merging = self.merge_radius_m > 0.0
        tracked = (self.network.coords[[t.peak_node() for t in bank]] if merging
                   else np.empty((0, 2)))
        for c in sorted(range(count), key=lambda c: (-peaks[c], c)):
            nodes = hot[labels == c]
            llr[nodes] = 0.0
            peak_xy = self.network.coords[nodes[np.argmax(field.llr[nodes])]]
            if tracked.size and np.min(np.hypot(*(tracked - peak_xy).T)) <= self.merge_radius_m:
                log.debug("detection within %g m of a tracker's peak: suppressed, no birth",
                          self.merge_radius_m)
                continue
            if merging:  # components of this step merge with each other too
                tracked = np.vstack([tracked.reshape(-1, 2), peak_xy])
            weight = field.llr[nodes]
            if self.weighting == "likelihood_ratio":
                weight = np.exp(weight - weight.max())
            prob = np.zeros(n)
            prob[nodes] = weight / weight.sum()
            log.info("detection: %d nodes with φ ≥ %g, peak φ=%.3g at node %d", nodes.size,
                     self.threshold, peaks[c], int(nodes[np.argmax(weight)]))
            bank = bank.with_birth(prob)
        return LikelihoodField(llr), bank

