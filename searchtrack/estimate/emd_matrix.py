"""The trackers × measurements EMD matrix of Algorithm 1 under the road metric (thesis §4.3).

Signatures. A diffused tracker or a Gaussian measurement density is
nonzero on almost every node, so each is *truncated*: keep the smallest set of nodes holding at
least ``support_mass`` (default 0.999) of its mass — the heaviest nodes, ties to the lower
index — and renormalise it to 1. By the triangle inequality for W1, the EMD between truncated
signatures differs from the full one by at most ``(1 − support_mass)`` times the farthest road
distance from a dropped node to the kept ones, per side; in practice far less
(``benchmarks/association.py`` prints the relative error).

Ground distance: road shortest-path distances in metres, exact (:class:`RoadMetric`).

The matrix is a solver family (:data:`EMD_MATRIX_BACKENDS`, :func:`solve_emd_matrix`); the
backend chooses the exact solver of each pair:

* ``"transport"`` (and ``"auto"``, the faster at these sizes): distances between the two truncated
  supports only, then the transportation LP (4.3)–(4.7) by the network simplex of
  :func:`~searchtrack.estimate.transport.emd`;
* ``"graph"``: :func:`~searchtrack.estimate.transport.emd_on_graph`, a min-cost flow on the whole
  road graph with the truncated signatures (no distances, but ~10 ms per pair on 8602 nodes).

Gate pruning. A pair whose EMD is *proven* ≥ ``gate_m`` is never solved and gets ``+inf`` (it
could not be associated anyway). A pair left unsolved (time limit, solver failure) also reads
``+inf`` in the cost matrix, but the result says so: :attr:`EMDMatrix.unsolved` marks it and the
status is ``FEASIBLE`` instead of ``OPTIMAL``.

Two lower bounds, both exact for the truncated signatures
``p`` (nodes ``i``) and ``q`` (nodes ``j``) and any optimal flow ``f`` (``Σ f = 1``):

* centroid bound, before any distance is computed: with ``κ`` =
  :attr:`RoadMetric.lower_bound_factor` (road distance ≥ ``κ`` × straight line),
  ``EMD = Σ f_ij d_ij ≥ κ Σ f_ij ‖ψ_i − ψ_j‖ ≥ κ ‖Σ f_ij (ψ_i − ψ_j)‖ = κ ‖ψ̄_p − ψ̄_q‖``
  (triangle inequality for the norm; the marginals of ``f`` are ``p`` and ``q``);
* nearest-support bound, from the distance block: ``Σ_ij f_ij d_ij ≥ Σ_i (Σ_j f_ij) min_j d_ij
  = Σ_i p_i min_j d_ij``, and symmetrically ``Σ_j q_j min_i d_ij``; both are at least the
  distance between the two supports' nearest nodes.

A relative slack of 1e-9 protects against round-off in the bounds.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.registry import Backend, Registry
from searchtrack.core.result import Result, Sense, Status
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.estimate.transport import emd, emd_on_graph
from searchtrack.estimate.transport.simplex import warm_up
from searchtrack.models.road_metric import RoadMetric, SourceDistances
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.emd_matrix")


_SLACK = 1e-9  # relative round-off allowance before a lower bound may skip a pair
_MASS_RTOL = 1e-9  # per-component masses must agree to this for a finite EMD


@dataclass(frozen=True, eq=False)
class Signature:
    """A truncated signature: ascending ``nodes`` and their ``weights`` (> 0, summing to 1)."""

    nodes: IntArray
    weights: FloatArray

    @property
    def size(self) -> int:
        """Number of support nodes."""
        return int(self.nodes.size)


def check_support_mass(support_mass: object) -> float:
    """``support_mass`` as a float in ``(0, 1]``, else :class:`InvalidInputError`."""
    if isinstance(support_mass, bool) or not isinstance(
            support_mass, (int, float, np.integer, np.floating)):
        raise InvalidInputError("support_mass", support_mass, "must be a number in (0, 1]")
    value = float(support_mass)
    if not 0.0 < value <= 1.0:
        raise InvalidInputError("support_mass", support_mass, "must be in (0, 1]")
    return value


def check_gate(gate_m: object, *, inf_ok: bool) -> float:
    """``gate_m`` as a positive float (finite unless ``inf_ok``)."""
    if isinstance(gate_m, bool) or not isinstance(gate_m, (int, float, np.integer, np.floating)):
        raise InvalidInputError("gate_m", gate_m, "must be a positive number of metres")
    value = float(gate_m)
    if math.isnan(value) or value <= 0.0 or (value == math.inf and not inf_ok):
        raise InvalidInputError("gate_m", gate_m, "must be positive" +
                                ("" if inf_ok else " and finite") + " (m)")
    return value


def distributions(name: str, values: ArrayLike, n_nodes: int) -> FloatArray:
    """``values`` as an ``(r, n_nodes)`` array of finite, non-negative rows with positive sums."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(name, values, "must be a 2-D array of numbers") from None
    if arr.ndim != 2 or arr.shape[1] != n_nodes:
        raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                f"must have shape (rows, {n_nodes}), one column per node")
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, f"<array of shape {arr.shape}>", "must be finite")
    if np.any(arr < 0.0):
        raise InvalidInputError(name, f"<array of shape {arr.shape}>", "must be non-negative")
    empty = np.flatnonzero(arr.sum(axis=1) <= 0.0)
    if empty.size:
        raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                f"row {int(empty[0])} has no mass")
    return arr


def truncate_signature(weights: ArrayLike, support_mass: float = 0.999) -> Signature:
    """The smallest node set holding ≥ ``support_mass`` of ``weights``' mass, renormalised.

    Nodes are taken heaviest first (ties: lower index first); ``support_mass = 1`` keeps every
    node of positive weight. Only nodes heavier than ``(1 − support_mass) · total / n`` are
    sorted: the lighter ones hold at most ``(1 − support_mass) · total`` together, so they are
    exactly the lightest nodes and never needed.

    Raises
    ------
    InvalidInputError
        ``weights`` not a non-empty 1-D array of finite non-negative numbers with a positive
        sum, or ``support_mass`` outside ``(0, 1]``.
    """
    mass = check_support_mass(support_mass)
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 1 or w.size == 0:
        raise InvalidInputError("weights", weights, "must be a non-empty 1-D array")
    return _truncate(distributions("weights", w[None, :], w.size)[0], mass)


def _truncate(w: FloatArray, mass: float) -> Signature:
    """:func:`truncate_signature` for a validated row ``w`` and ``mass``."""
    total = float(w.sum())
    if mass >= 1.0:
        nodes = np.flatnonzero(w > 0.0)
    else:
        cand = np.flatnonzero(w > (1.0 - mass) * total / w.size)
        order = cand[np.lexsort((cand, -w[cand]))]
        k = int(np.searchsorted(np.cumsum(w[order]), mass * total)) + 1
        nodes = np.sort(order[:min(k, order.size)])
    nodes = nodes.astype(np.int64)
    kept = w[nodes] / w[nodes].sum()
    nodes.setflags(write=False)
    kept.setflags(write=False)
    return Signature(nodes, kept)


@dataclass(frozen=True, eq=False)
class EMDMatrixProblem:
    """The ``(k, q)`` EMD matrix to compute: tracker rows against measurement-density rows.

    Build it with :meth:`build` (validates); the fields are the validated arrays.
    """

    metric: RoadMetric
    trackers: FloatArray
    measured: FloatArray
    support_mass: float = 0.999
    gate_m: float = math.inf

    @classmethod
    def build(cls, network: RoadNetwork | RoadMetric, bank_probabilities: ArrayLike,
              densities: ArrayLike, *, support_mass: float = 0.999,
              gate_m: float = math.inf) -> EMDMatrixProblem:
        """Validate the inputs of :func:`emd_matrix` (same parameters) into a problem."""
        if not isinstance(network, (RoadNetwork, RoadMetric)):
            raise InvalidInputError("network", network, "must be a RoadNetwork or a RoadMetric")
        metric = network if isinstance(network, RoadMetric) else RoadMetric(network)
        n = metric.n_nodes
        return cls(metric, distributions("bank_probabilities", bank_probabilities, n),
                   distributions("densities", densities, n), check_support_mass(support_mass),
                   check_gate(gate_m, inf_ok=True))

    @property
    def shape(self) -> tuple[int, int]:
        """``(k, q)``: trackers × measurements."""
        return (self.trackers.shape[0], self.measured.shape[0])


@dataclass(frozen=True, eq=False)
class EMDMatrix:
    """The plan: ``costs[i, j]`` is the EMD (m) of tracker ``i`` and measurement ``j``, ``+inf``
    where proven ≥ the gate, where mass cannot cross between road components, or where
    ``unsolved[i, j]`` (the pair was not solved: time limit or solver failure)."""

    costs: FloatArray
    unsolved: BoolArray


def _solver(name: str) -> Any:
    def solve(problem: EMDMatrixProblem, *, time_limit_s: float,
              seed: int) -> Result[EMDMatrix]:
        return _solve(problem, name, time_limit_s)

    return solve


EMD_MATRIX_BACKENDS: Registry[EMDMatrixProblem, EMDMatrix] = Registry("emd_matrix")
EMD_MATRIX_BACKENDS.register(Backend("auto", _solver("transport"), True,
                                     "the transport backend (the faster at road sizes)"))
EMD_MATRIX_BACKENDS.register(Backend(
    "transport", _solver("transport"), True,
    "distances between the truncated supports, then the network simplex per pair"))
EMD_MATRIX_BACKENDS.register(Backend(
    "graph", _solver("graph"), True, "a min-cost flow on the whole road graph per pair"))


def solve_emd_matrix(problem: EMDMatrixProblem, *, backend: str = "auto",
                     time_limit_s: float = 10.0, seed: int = 0) -> Result[EMDMatrix]:
    """The EMD matrix of ``problem`` with the named backend within ``time_limit_s``.

    ``OPTIMAL`` when every pair is exact or proven ≥ the gate; ``FEASIBLE`` when some pair was
    left unsolved or is only an upper bound (the message counts them). ``objective`` is the sum
    of the finite entries (m), ``sense`` minimise.

    Raises
    ------
    InvalidInputError
        Unknown backend, bad time limit or seed.
    """
    return EMD_MATRIX_BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)


def emd_matrix(
    network: RoadNetwork | RoadMetric,
    bank_probabilities: ArrayLike,
    densities: ArrayLike,
    *,
    support_mass: float = 0.999,
    gate_m: float = math.inf,
    backend: str = "auto",
    time_limit_s: float = 10.0,
) -> FloatArray:
    """``(k, q)`` EMD (m) between each tracker and each measurement density (Algorithm 1, ``DA``).

    The cost matrix of :func:`solve_emd_matrix`, for callers that only want the numbers.

    Parameters
    ----------
    network
        The road network, or a prebuilt :class:`RoadMetric` of it (pass one when calling
        repeatedly: building it costs ~0.1 s on a city map).
    bank_probabilities
        ``(k, n)`` tracker distributions (rows need not be normalised), e.g.
        ``TrackerBank.probabilities()``.
    densities
        ``(q, n)`` measurement densities ``Û`` (§4.3).
    support_mass
        Mass kept by the signature truncation, in ``(0, 1]`` (module docstring).
    gate_m
        Pairs proven to have EMD ≥ ``gate_m`` are skipped and get ``+inf``; ``inf`` (default)
        computes every pair.
    backend
        A name of :data:`EMD_MATRIX_BACKENDS`: ``"auto"``, ``"transport"`` or ``"graph"``.
    time_limit_s
        Wall-clock limit for the whole matrix; pairs not solved in time get ``+inf`` (logged).

    Returns
    -------
    ``(k, q)`` EMDs in metres: exact for solved pairs, ``+inf`` for skipped pairs and for pairs
    whose mass cannot reach across disconnected components.

    Raises
    ------
    InvalidInputError
        A bad shape or entry (naming ``bank_probabilities`` or ``densities``), ``support_mass``,
        ``gate_m``, ``backend``, ``time_limit_s`` or ``network``.
    """
    problem = EMDMatrixProblem.build(network, bank_probabilities, densities,
                                     support_mass=support_mass, gate_m=gate_m)
    result = solve_emd_matrix(problem, backend=backend, time_limit_s=time_limit_s)
    if result.plan is None:
        return np.full(problem.shape, math.inf)
    return result.plan.costs


def _solve(problem: EMDMatrixProblem, method: str, time_limit_s: float) -> Result[EMDMatrix]:
    """Every pair of ``problem`` with the ``method`` pair solver (``"transport"``/``"graph"``)."""
    warm_up()
    deadline = Deadline(time_limit_s)
    metric, gate_m = problem.metric, problem.gate_m
    sig_t = [_truncate(row, problem.support_mass) for row in problem.trackers]
    sig_q = [_truncate(row, problem.support_mass) for row in problem.measured]
    out = np.full((len(sig_t), len(sig_q)), math.inf)
    unsolved = np.zeros(out.shape, dtype=bool)
    pairs = np.argwhere(centroid_bound(metric, sig_t, sig_q) < gate_m * (1.0 + _SLACK))
    pair_solver = (None if pairs.size == 0 else _GraphPairs(metric) if method == "graph"
                   else _TransportPairs(metric, sig_t, sig_q, pairs))
    inexact = 0
    for i, j in pairs:
        if deadline.expired():
            unsolved[i, j] = True
            continue
        assert pair_solver is not None
        value, exact = pair_solver(int(i), int(j), sig_t[i], sig_q[j], gate_m, deadline)
        out[i, j] = value
        unsolved[i, j] = exact is None
        inexact += exact is False
    late = int(unsolved.sum())
    if late:
        log.warning("emd_matrix: %d of %d pairs left unsolved at +inf (time limit %.3g s or "
                    "solver failure)", late, len(pairs), time_limit_s)
    out.setflags(write=False)
    unsolved.setflags(write=False)
    finite = out[np.isfinite(out)]
    total = float(finite.sum())
    proven = late == 0 and inexact == 0
    note = f"{len(pairs)} of {out.size} pairs solved within the gate"
    if late or inexact:
        note += f"; {late} unsolved, {inexact} only upper bounds"
    return Result(Status.OPTIMAL if proven else Status.FEASIBLE, total,
                  total if proven else None, deadline.elapsed(), method,
                  EMDMatrix(out, unsolved), sense=Sense.MINIMIZE, message=note,
                  stats={"pairs": float(len(pairs)), "unsolved": float(late)})


def checked_emd_matrix(metric: RoadMetric, trackers: FloatArray, measured: FloatArray,
                       support_mass: float, gate_m: float, backend: str,
                       time_limit_s: float) -> FloatArray:
    """:func:`emd_matrix` for arguments the caller has already validated."""
    problem = EMDMatrixProblem(metric, trackers, measured, support_mass, gate_m)
    result = solve_emd_matrix(problem, backend=backend, time_limit_s=time_limit_s)
    return result.plan.costs if result.plan is not None else np.full(problem.shape, math.inf)


#: Names of the pair solvers (the backends of :data:`EMD_MATRIX_BACKENDS`).
METHODS: tuple[str, ...] = tuple(EMD_MATRIX_BACKENDS.names())


def centroid_bound(metric: RoadMetric, left: list[Signature],
                   right: list[Signature]) -> FloatArray:
    """``(len(left), len(right))`` lower bounds ``κ ‖ψ̄_p − ψ̄_q‖`` on the EMD (m)."""
    xy = metric.network.coords

    def centroids(sigs: list[Signature]) -> FloatArray:
        return np.array([s.weights @ xy[s.nodes] for s in sigs]).reshape(len(sigs), 2)

    a, b = centroids(left), centroids(right)
    gap = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return np.asarray(metric.lower_bound_factor * gap, dtype=np.float64)


def nearest_support_bound(cost: FloatArray, p: FloatArray, q: FloatArray) -> float:
    """``max(Σ_i p_i min_j d_ij, Σ_j q_j min_i d_ij)`` ≤ EMD (``inf`` if some mass is cut off)."""
    return float(max(p @ cost.min(axis=1), q @ cost.min(axis=0)))


def _value(result: Result[Any], what: str) -> tuple[float, bool | None]:
    """The EMD of a solve and whether it is exact: ``(objective, True)`` when optimal,
    ``(inf, True)`` when infeasible (mass cannot cross components), ``(objective, False)`` for
    an unproven plan, ``(inf, None)`` when the solve gave nothing (the pair is unsolved)."""
    if result.status is Status.INFEASIBLE:
        return math.inf, True
    if result.status is Status.FEASIBLE and result.objective is not None:
        log.warning("%s: EMD not proven optimal (%s); using the upper bound", what,
                    result.message)
        return float(result.objective), False
    if result.status is Status.OPTIMAL and result.objective is not None:
        return float(result.objective), True
    log.warning("%s: no EMD (%s: %s); pair left unsolved", what, result.status.name,
                result.message)
    return math.inf, None


@dataclass(frozen=True, eq=False)
class _GraphPairs:
    """Solve a pair as a min-cost flow on the whole road graph."""

    metric: RoadMetric

    def __call__(self, i: int, j: int, p: Signature, q: Signature, gate: float,
                 deadline: Deadline) -> tuple[float, bool | None]:
        n = self.metric.n_nodes
        pv, qv = np.zeros(n), np.zeros(n)
        pv[p.nodes], qv[q.nodes] = p.weights, q.weights
        result = emd_on_graph(self.metric.network.adjacency, pv, qv,
                              time_limit_s=max(deadline.remaining(), 1e-3))
        return _value(result, f"emd_on_graph (tracker {i}, measurement {j})")


class _TransportPairs:
    """Solve a pair as a transportation problem between the two supports.

    The *source side* is the side (trackers or measurements) whose candidate supports hold
    fewer nodes, usually the measurements. One :class:`SourceDistances` covers all of its
    candidate support nodes; then, per source signature, one distance block to the union of the
    supports it is paired with, which each pair slices.
    """

    def __init__(self, metric: RoadMetric, sig_t: list[Signature], sig_q: list[Signature],
                 pairs: IntArray) -> None:
        self.metric = metric
        t_nodes = np.unique(np.concatenate([sig_t[i].nodes for i in np.unique(pairs[:, 0])]))
        q_nodes = np.unique(np.concatenate([sig_q[j].nodes for j in np.unique(pairs[:, 1])]))
        self.from_measurements = bool(q_nodes.size <= t_nodes.size)
        self.sources = q_nodes if self.from_measurements else t_nodes
        self.distances: SourceDistances = metric.from_nodes(self.sources)
        src_col, dst_col = (1, 0) if self.from_measurements else (0, 1)
        src_sigs, dst_sigs = (sig_q, sig_t) if self.from_measurements else (sig_t, sig_q)
        self.src_sigs, self.dst_sigs = src_sigs, dst_sigs
        self.partners = {int(k): pairs[pairs[:, src_col] == k, dst_col]
                         for k in np.unique(pairs[:, src_col])}
        self.blocks: dict[int, tuple[IntArray, FloatArray]] = {}

    def _source_block(self, k: int) -> tuple[IntArray, FloatArray]:
        """Target nodes (all partners of source signature ``k``) and the distances to them."""
        if k not in self.blocks:
            targets = np.unique(np.concatenate([self.dst_sigs[m].nodes
                                                for m in self.partners[k]]))
            among = np.searchsorted(self.sources, self.src_sigs[k].nodes)
            self.blocks[k] = targets, self.distances.to(targets, among)
        return self.blocks[k]

    def block(self, i: int, j: int) -> FloatArray:
        """``(|S_i|, |S_j|)`` road distances between tracker ``i``'s and measurement ``j``'s
        supports."""
        k, m = (j, i) if self.from_measurements else (i, j)
        targets, dist = self._source_block(k)
        cols = np.searchsorted(targets, self.dst_sigs[m].nodes)
        return dist[:, cols].T if self.from_measurements else dist[:, cols]

    def __call__(self, i: int, j: int, p: Signature, q: Signature, gate: float,
                 deadline: Deadline) -> tuple[float, bool | None]:
        cost = self.block(i, j)
        if nearest_support_bound(cost, p.weights, q.weights) >= gate * (1.0 + _SLACK):
            return math.inf, True
        what = f"emd (tracker {i}, measurement {j})"
        if np.isfinite(cost).all():
            return _value(emd(p.weights, q.weights, cost,
                              time_limit_s=max(deadline.remaining(), 1e-3)), what)
        return self._by_component(cost, p, q, deadline, what)

    def _by_component(self, cost: FloatArray, p: Signature, q: Signature, deadline: Deadline,
                      what: str) -> tuple[float, bool | None]:
        """EMD when the supports span several components: finite only if every component
        holds the same mass on both sides, then the mass-weighted sum of per-component EMDs."""
        cp, cq = self.metric.component[p.nodes], self.metric.component[q.nodes]
        size = int(max(cp.max(), cq.max())) + 1
        mp = np.bincount(cp, weights=p.weights, minlength=size)
        mq = np.bincount(cq, weights=q.weights, minlength=size)
        if np.abs(mp - mq).max() > _MASS_RTOL:
            return math.inf, True
        total, exact = 0.0, True
        for c in np.flatnonzero(mp > 0.0):
            rows, cols = cp == c, cq == c
            value, ok = _value(emd(p.weights[rows], q.weights[cols], cost[np.ix_(rows, cols)],
                                   time_limit_s=max(deadline.remaining(), 1e-3)), what)
            if ok is None:
                return math.inf, None
            total += float(mp[c]) * value
            exact = exact and ok
        return total, exact
