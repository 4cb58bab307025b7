"""The belief seam between estimation and planning: what a planner may ask of a belief on nodes.

Planners score candidate actions with a reward that takes a belief (the Stone Soup sensor-manager
seam), so they are written against these protocols, never against the concrete estimators:

- :class:`NodeBelief`: a mass over the road nodes. The likelihood-ratio field, one node tracker
  and a bank of trackers all satisfy it.
- :class:`TrackBelief`: one target's location, a :class:`NodeBelief` of mass 1 with a stable
  ``track_id`` (a :class:`~searchtrack.estimate.node_tracker.NodeTracker`).
- :class:`BeliefBank`: the live track beliefs, indexed ``0 .. len − 1``
  (a :class:`~searchtrack.estimate.node_tracker.TrackerBank`).
- :class:`SearchField`: the per-node score a search law climbs, the log-likelihood ratio ``φ``
  of the undetected targets for the gradient force (5.6)–(5.7)
  (a :class:`~searchtrack.estimate.lrt.LikelihoodField`).
- :class:`NodePredictor`: one prediction step of a node belief over ``dt_s`` seconds, and
  :class:`SparseNodePredictor`, which also exposes its one-step matrix so that a local belief can
  be propagated on its support only (a :class:`~searchtrack.estimate.diffusion.GraphDiffusion`).
- :class:`RoadParticleBelief`: ``M`` targets as weighted particles ``(directed edge, arc
  length)`` on a :class:`~searchtrack.models.road_particles.DirectedRoads` (paper 000's road
  particle filters), with one entropy per target; what the road-search planners read.
- :class:`LabelledParticleBelief`: a labelled multi-Bernoulli density as per-label particle sets
  and existence probabilities (Nguyen et al.'s radio-tag TBD-LMB filter,
  :class:`~searchtrack.estimate.radio.tbd.TbdLmbFilter`, and the plain store
  :class:`~searchtrack.estimate.labelled_particles.LabelledParticles`); what the radio planners
  read.

All are ``runtime_checkable``: a planner checks its inputs with ``isinstance`` against them.
"""

from __future__ import annotations

from typing import Any, Protocol, runtime_checkable

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.types import FloatArray


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


@runtime_checkable
class TrackBelief(NodeBelief, Protocol):
    """One tracked target's location: a :class:`NodeBelief` of mass 1 and its identity."""

    @property
    def track_id(self) -> int:
        """The track's identity: stable while it lives, unique within its bank."""
        ...


@runtime_checkable
class BeliefBank(Protocol):
    """The live track beliefs on one road network, in a fixed order (index ``0 .. len − 1``)."""

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n`` every belief of the bank is on."""
        ...

    def __len__(self) -> int:
        """Number of live tracks."""
        ...

    def __getitem__(self, index: int) -> TrackBelief:
        """Track ``index`` (``0 ≤ index < len``)."""
        ...


@runtime_checkable
class SearchField(Protocol):
    """The per-node score a search law climbs: for the LRT, the log-likelihood ratio ``φ``
    (3.3) whose edge differences ``Bᵀφ`` drive the gradient force (5.6)–(5.7)."""

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n``."""
        ...

    def node_score(self) -> FloatArray:
        """``(n,)`` finite score per node, higher where a target is more likely (read-only)."""
        ...


@runtime_checkable
class NodePredictor(Protocol):
    """One prediction step of a node belief, ``Δt = dt_s`` seconds ahead (e.g. (4.2))."""

    @property
    def n_nodes(self) -> int:
        """Number of road nodes ``n``."""
        ...

    @property
    def dt_s(self) -> float:
        """The step ``Δt`` (s)."""
        ...

    def propagate(self, values: FloatArray) -> FloatArray:
        """``(n,)`` values one step later (a new array; the input is unchanged)."""
        ...


@runtime_checkable
class SparseNodePredictor(NodePredictor, Protocol):
    """A :class:`NodePredictor` whose step is ``decay_factor · A x`` for a symmetric sparse
    ``A`` (``e^{−αLΔt}``, (3.8) and (4.2)), so a local belief can be propagated on its support:
    ``A`` symmetric means the columns the support needs are its rows."""

    @property
    def operator(self) -> Any:
        """The symmetric sparse ``(n, n)`` matrix ``A`` (CSR), or ``None`` when not built."""
        ...

    @property
    def decay_factor(self) -> float:
        """The scalar each step multiplies by besides ``A`` (1 without decay)."""
        ...


@runtime_checkable
class RoadParticleBelief(Protocol):
    """``M`` targets, each a weighted particle cloud on directed roads (Moore et al. 2021, Eq. 8).

    ``target_particles()`` returns ``(edge, s, w)``, each ``(M, N)``: directed edge index,
    arc length (m) from the edge's tail, and weights summing to 1 per target. For a
    Rao-Blackwellized filter these are the clouds of the association hypothesis the planner
    should use (the best top-level particle). ``target_entropy()`` is ``(M,)`` in nats (Eq. 19,
    on road bins).
    """

    @property
    def roads(self) -> Any:
        """The :class:`~searchtrack.models.road_particles.DirectedRoads` the particles live on."""
        ...

    @property
    def n_targets(self) -> int:
        """Number of targets ``M``."""
        ...

    def target_particles(self) -> tuple[NDArray[np.int64], FloatArray, FloatArray]:
        """``(edge, s, w)``, each ``(M, N)`` (new arrays the caller may change)."""
        ...

    def target_entropy(self) -> FloatArray:
        """``(M,)`` entropy (nats) of each target's position on road bins."""
        ...


@runtime_checkable
class LabelledParticleBelief(Protocol):
    """A labelled multi-Bernoulli density on particles (Nguyen et al., §III-C, eqs. 24–30).

    For each of ``Λ`` labels ``λ`` (tag frequencies, row ``λ`` of every array) an existence
    probability ``r_λ`` and ``N`` weighted particles of the state ``[px, vx, py, vy]``, the motion
    mode and the pulse offset ``τ``. Planners read these arrays and predict and update their own
    copy (:mod:`~searchtrack.estimate.labelled_particles`); they never change the belief's.
    :class:`~searchtrack.estimate.labelled_particles.LabelledParticles` is the plain one.
    """

    @property
    def x(self) -> FloatArray:
        """``(Λ, N, 4)`` particle states ``[px, vx, py, vy]`` (m, m/s)."""
        ...

    @property
    def mode(self) -> NDArray[np.integer[Any]]:
        """``(Λ, N)`` integer motion modes (0 = WD, 1 = CV)."""
        ...

    @property
    def tau(self) -> FloatArray:
        """``(Λ, N)`` pulse offsets ``τ`` (s) in ``[0, T0)``."""
        ...

    @property
    def w(self) -> FloatArray:
        """``(Λ, N)`` non-negative particle weights, each label's summing to 1."""
        ...

    @property
    def r(self) -> FloatArray:
        """``(Λ,)`` existence probabilities ``r_λ`` in ``[0, 1]``."""
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
