"""Bayesian node trackers (thesis 001, Ch. 4): one location distribution per detected target.

Roles, one verb each: :class:`TrackerPredictor` (diffusion, (4.2)/(4.8)), :func:`update_tracker`
(Gaussian position measurement, Algorithm 1 line 11), :class:`TrackerDeleter` (dissolution below
``P_min``, §4.2). Trackers are born by :class:`~searchtrack.estimate.lrt.LRTInitiator`.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Iterator
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.checks import node_vector, points, positive, real
from searchtrack.core.errors import InvalidInputError
from searchtrack.estimate.belief import entropy_nats
from searchtrack.estimate.diffusion import GraphDiffusion
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.node_tracker")

_MASS_TOL = 1e-6


@dataclass(frozen=True, eq=False)
class NodeTracker:
    """One target's location distribution over the road nodes; a
    :class:`~searchtrack.estimate.belief.TrackBelief`.

    Parameters
    ----------
    probability
        ``(n,)`` non-negative, summing to 1 within 1e-6 (it is rescaled to sum to 1 exactly).
    track_id
        The tracker's identity, unique within its :class:`TrackerBank`.
    """

    probability: NDArray[np.float64]
    track_id: int = 0

    def __post_init__(self) -> None:
        p = np.array(node_vector("probability", self.probability), copy=True)
        total = float(p.sum())
        if np.any(p < 0.0) or abs(total - 1.0) > _MASS_TOL:
            raise InvalidInputError("probability", self.probability,
                                    f"must be non-negative and sum to 1 (sums to {total:.6g})")
        p /= total
        p.setflags(write=False)
        object.__setattr__(self, "probability", p)
        if isinstance(self.track_id, bool) or not isinstance(self.track_id, (int, np.integer)):
            raise InvalidInputError("track_id", self.track_id, "must be an integer")

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n``."""
        return int(self.probability.size)

    def node_probability(self) -> NDArray[np.float64]:
        """A copy of the ``(n,)`` location probabilities."""
        return np.array(self.probability, copy=True)

    def mass(self) -> float:
        """Always 1: a live tracker holds one target."""
        return 1.0

    def peak_node(self) -> int:
        """Node of highest probability, ``ψ(max P)`` in the thesis (lowest index on ties)."""
        return int(np.argmax(self.probability))

    @property
    def peak_probability(self) -> float:
        """The highest node probability, compared with ``P_min`` for dissolution."""
        return float(self.probability.max())

    def entropy(self) -> float:
        """Shannon entropy (nats); ``log n`` for a uniform tracker."""
        return entropy_nats(self.probability)


@dataclass(frozen=True, eq=False)
class TrackerBank:
    """The live trackers, in birth order: a :class:`~searchtrack.estimate.belief.BeliefBank`,
    and a :class:`~searchtrack.estimate.belief.NodeBelief` whose mass is their number.

    ``node_probability()`` is the sum of the trackers' distributions (the expected number of
    tracked targets on each node). ``next_id`` is the identity the next born tracker gets.
    """

    n_nodes: int
    trackers: tuple[NodeTracker, ...] = field(default=())
    next_id: int = 0

    def __post_init__(self) -> None:
        if isinstance(self.n_nodes, bool) or not isinstance(self.n_nodes, (int, np.integer)) \
                or self.n_nodes < 1:
            raise InvalidInputError("n_nodes", self.n_nodes, "must be an integer ≥ 1")
        trackers = tuple(self.trackers)
        if any(not isinstance(t, NodeTracker) or t.n_nodes != self.n_nodes for t in trackers):
            raise InvalidInputError("trackers", self.trackers,
                                    f"must be NodeTrackers on {self.n_nodes} nodes")
        ids = [int(t.track_id) for t in trackers]
        if len(set(ids)) != len(ids) or any(i < 0 or i >= self.next_id for i in ids):
            raise InvalidInputError("trackers", ids, f"ids must be unique, in [0, {self.next_id})")
        object.__setattr__(self, "trackers", trackers)

    def __len__(self) -> int:
        return len(self.trackers)

    def __iter__(self) -> Iterator[NodeTracker]:
        return iter(self.trackers)

    def __getitem__(self, index: int) -> NodeTracker:
        return self.trackers[index]

    def with_birth(self, probability: ArrayLike) -> TrackerBank:
        """A bank with one more tracker, holding ``probability`` and identity ``next_id``."""
        born = NodeTracker(np.asarray(probability, dtype=np.float64), self.next_id)
        log.info("tracker %d born, peak node %d (p=%.3f)", born.track_id, born.peak_node(),
                 born.peak_probability)
        return TrackerBank(self.n_nodes, (*self.trackers, born), self.next_id + 1)

    def with_trackers(self, trackers: tuple[NodeTracker, ...]) -> TrackerBank:
        """A bank holding ``trackers`` instead, with the same ``next_id``."""
        return TrackerBank(self.n_nodes, trackers, self.next_id)

    def probabilities(self) -> NDArray[np.float64]:
        """``(k, n)`` array: row ``l`` is tracker ``l``'s distribution."""
        if not self.trackers:
            return np.zeros((0, self.n_nodes))
        return np.stack([t.probability for t in self.trackers])

    def node_probability(self) -> NDArray[np.float64]:
        """``(n,)`` sum of the trackers' distributions (zeros for an empty bank)."""
        return np.asarray(self.probabilities().sum(axis=0), dtype=np.float64)

    def mass(self) -> float:
        """Number of live trackers."""
        return float(len(self.trackers))

    def peak_node(self) -> int:
        """Node of highest summed probability; an empty bank has none."""
        if not self.trackers:
            raise InvalidInputError("trackers", (), "an empty bank has no peak node")
        return int(np.argmax(self.node_probability()))

    def entropy(self) -> float:
        """Entropy (nats) of the normalized sum; 0 for an empty bank."""
        return entropy_nats(self.node_probability())


@dataclass(frozen=True, eq=False)
class TrackerPredictor:
    """Mass-conserving random-walk prediction ``P_{k+1} = e^{−αLΔt} ℙ_k`` ((4.2), (4.8))."""

    diffusion: GraphDiffusion

    def __post_init__(self) -> None:
        if not math.isinf(self.diffusion.decay_c):
            raise InvalidInputError("diffusion", self.diffusion.decay_c,
                                    "tracker diffusion must not decay (decay_c = inf), (4.1)")

    def predict(self, bank: TrackerBank) -> TrackerBank:
        """Every tracker diffused by one step, in one sparse product for the whole bank.

        Round-off negatives (≈1e-17) are clipped to 0 and each column renormalized.
        """
        if bank.n_nodes != self.diffusion.n_nodes:
            raise InvalidInputError("bank", bank.n_nodes,
                                    f"must be on {self.diffusion.n_nodes} nodes")
        if not bank.trackers:
            return bank
        moved = self.diffusion.propagate(bank.probabilities().T)
        np.maximum(moved, 0.0, out=moved)
        moved /= moved.sum(axis=0)
        return bank.with_trackers(tuple(
            NodeTracker(moved[:, k], t.track_id) for k, t in enumerate(bank.trackers)
        ))


def position_log_likelihood(
    network: RoadNetwork, positions_m: ArrayLike, noise_sd_m: float
) -> NDArray[np.float64]:
    """``(k, n)`` log of the node-wise measurement density ``U_k^j`` (§4.3), constant dropped.

    Row ``q`` is ``−‖ξ̃_q − ψ(v)‖² / (2 s²)`` over the nodes ``v``: the Gaussian of the thesis in
    the Euclidean distance from the measured point ``ξ̃_q`` to each node, noise s.d. ``s``.
    """
    xy = points("positions_m", positions_m)
    s = positive("noise_sd_m", noise_sd_m)
    c = network.coords
    d2 = np.subtract.outer(xy[:, 0], c[:, 0]) ** 2 + np.subtract.outer(xy[:, 1], c[:, 1]) ** 2
    return np.asarray(-d2 / (2.0 * s * s), dtype=np.float64)


def measurement_density(log_likelihood: NDArray[np.float64]) -> NDArray[np.float64]:
    """The normalized densities ``Û_k^j`` (§4.3): each row of ``exp(log_likelihood)`` scaled to
    sum to 1, computed without underflow."""
    ll = np.atleast_2d(log_likelihood)
    w = np.exp(ll - ll.max(axis=1, keepdims=True))
    return np.asarray(w / w.sum(axis=1, keepdims=True), dtype=np.float64)


def update_tracker(tracker: NodeTracker, log_likelihood: ArrayLike) -> NodeTracker:
    """Posterior ``ℙ ∝ P × Û`` for one associated measurement (Algorithm 1, line 11), normalized.

    ``log_likelihood`` is one row of :func:`position_log_likelihood`; the product is formed in
    the log domain so that a measurement far from the tracker's support cannot underflow to 0.
    """
    ll = node_vector("log_likelihood", log_likelihood, tracker.n_nodes)
    prior = tracker.probability
    support = prior > 0.0
    shifted = np.zeros_like(prior)
    shifted[support] = np.exp(ll[support] - ll[support].max())
    post = prior * shifted
    return NodeTracker(post / post.sum(), tracker.track_id)


@dataclass(frozen=True)
class TrackerDeleter:
    """Dissolve trackers whose peak probability fell below ``P_min`` (§4.2, §4.3; 0.07)."""

    p_min: float = 0.07

    def __post_init__(self) -> None:
        p = real("p_min", self.p_min)
        if not 0.0 <= p <= 1.0:
            raise InvalidInputError("p_min", self.p_min, "must be in [0, 1]")
        object.__setattr__(self, "p_min", p)

    def delete(self, bank: TrackerBank) -> TrackerBank:
        """The bank without the trackers whose ``max P < P_min``."""
        keep = tuple(t for t in bank.trackers if t.peak_probability >= self.p_min)
        if len(keep) == len(bank.trackers):
            return bank
        gone = sorted(set(t.track_id for t in bank.trackers) - set(t.track_id for t in keep))
        log.info("trackers %s dissolved (peak below P_min=%g)", gone, self.p_min)
        return bank.with_trackers(keep)
