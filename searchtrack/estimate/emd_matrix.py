"""The trackers × measurements EMD matrix of Algorithm 1 under the road metric (thesis §4.3).

Signatures are truncated (:mod:`.signatures`).

Ground distance: road shortest-path distances in metres, exact (:class:`RoadMetric`'s junction
table, or Dijkstra on the road graph).

The matrix is a solver family (:data:`EMD_MATRIX_BACKENDS`, :func:`solve_emd_matrix`); the
backend chooses the exact solver of each pair:

* ``"transport"`` (and ``"auto"``, the faster at these sizes): road distances between the two
  truncated supports only (from :class:`RoadMetric`'s junction table when it has one, else by
  one Dijkstra per end junction of the smaller side's supports on the junction graph, stopped
  at twice a finite gate or once every partner's end junction is settled:
  :mod:`~searchtrack.estimate.transport.road_blocks`), then the transportation LP (4.3)–(4.7)
  by the network simplex (:func:`~searchtrack.estimate.transport.pair_emd.pair_emd`, the
  network simplex of :func:`~searchtrack.estimate.transport.emd` without its per-call
  validation, which it falls back to). Entries beyond the
  limit enter as the limit (a lower bound), so the EMD solved is a lower bound: ``+inf`` when it
  reaches the gate, exact when its plan uses no such entry, else solved again on exact
  distances;
* ``"graph"``: :func:`~searchtrack.estimate.transport.emd_on_graph`, a min-cost flow on the whole
  road graph with the truncated signatures (no distances, but ~10 ms per pair on 8602 nodes).

Gate pruning. A pair whose EMD is *proven* ≥ ``gate_m`` is never solved and gets ``+inf`` (it
could not be associated anyway). A pair left unsolved (time limit, solver failure) also reads
``+inf`` in the cost matrix, but the result says so: :attr:`EMDMatrix.unsolved` marks it and the
status is ``FEASIBLE`` instead of ``OPTIMAL``.

Pairs are skipped on the lower bounds of :mod:`.signatures` (centroid, then nearest support),
with a relative slack of 1e-9 against round-off.
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
from searchtrack.estimate.signatures import (
    SLACK,
    Signature,
    centroid_bound,
    check_gate,
    check_support_mass,
    distributions,
    nearest_support_bound,
    truncate_rows,
)
from searchtrack.estimate.transport import emd, emd_on_graph
from searchtrack.estimate.transport.pair_batch import solve_sources
from searchtrack.estimate.transport.pair_emd import PairEMD, pair_emd
from searchtrack.estimate.transport.road_blocks import PairBlocks
from searchtrack.estimate.transport.simplex import KERNEL_SET, warm_up
from searchtrack.models.road_metric import RoadMetric
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.estimate.emd_matrix")


_MASS_RTOL = 1e-9  # per-component masses must agree to this for a finite EMD
_LIMIT_FACTOR = 2.0  # Dijkstra stops at this multiple of a finite gate


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
                                     "the transport backend (the faster at road sizes)",
                                     kernels=(KERNEL_SET,)))
EMD_MATRIX_BACKENDS.register(Backend(
    "transport", _solver("transport"), True,
    "distances between the truncated supports, then the network simplex per pair",
    kernels=(KERNEL_SET,)))
EMD_MATRIX_BACKENDS.register(Backend(
    "graph", _solver("graph"), True, "a min-cost flow on the whole road graph per pair",
    kernels=(KERNEL_SET,)))


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
    sig_t = truncate_rows(problem.trackers, problem.support_mass)
    sig_q = truncate_rows(problem.measured, problem.support_mass)
    out = np.full((len(sig_t), len(sig_q)), math.inf)
    unsolved = np.zeros(out.shape, dtype=bool)
    pairs = np.argwhere(centroid_bound(metric, sig_t, sig_q) < gate_m * (1.0 + SLACK))
    pair_solver = (None if pairs.size == 0 else _GraphPairs(metric) if method == "graph"
                   else _TransportPairs(metric, sig_t, sig_q, pairs, gate_m))
    batched, done = (pair_solver.batch(pairs, gate_m, deadline)
                     if isinstance(pair_solver, _TransportPairs) else (None, None))
    inexact = timed_out = 0
    for n, (i, j) in enumerate(pairs):
        if done is not None and batched is not None and done[n]:
            out[i, j] = batched[n]
            continue
        if deadline.expired():
            unsolved[i, j] = True
            timed_out += 1
            continue
        assert pair_solver is not None
        value, exact = pair_solver(int(i), int(j), sig_t[i], sig_q[j], gate_m, deadline)
        out[i, j] = value
        unsolved[i, j] = exact is None
        inexact += exact is False
    late = int(unsolved.sum())
    if timed_out:
        log.warning("emd_matrix: %d of %d pairs left unsolved at +inf: time limit %.3g s "
                    "reached", timed_out, len(pairs), time_limit_s)
    if late > timed_out:
        log.warning("emd_matrix: %d of %d pairs left unsolved at +inf: the pair solver "
                    "failed (see the warnings above)", late - timed_out, len(pairs))
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
                  stats={"pairs": float(len(pairs)), "unsolved": float(late),
                         "refined": float(getattr(pair_solver, "refined", 0))})


def checked_emd_matrix(metric: RoadMetric, trackers: FloatArray, measured: FloatArray,
                       support_mass: float, gate_m: float, backend: str,
                       time_limit_s: float) -> FloatArray:
    """:func:`emd_matrix` for arguments the caller has already validated."""
    problem = EMDMatrixProblem(metric, trackers, measured, support_mass, gate_m)
    result = solve_emd_matrix(problem, backend=backend, time_limit_s=time_limit_s)
    return result.plan.costs if result.plan is not None else np.full(problem.shape, math.inf)


#: Names of the pair solvers (the backends of :data:`EMD_MATRIX_BACKENDS`).
METHODS: tuple[str, ...] = tuple(EMD_MATRIX_BACKENDS.names())


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


def _pair_value(solved: PairEMD, what: str) -> tuple[float, bool | None]:
    """:func:`_value` of a :func:`~searchtrack.estimate.transport.pair_emd.pair_emd` outcome."""
    if solved.result is not None:
        return _value(solved.result, what)
    if solved.status is Status.INFEASIBLE:
        return math.inf, True
    assert solved.value is not None
    return solved.value, True


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

    Distances come from :class:`~searchtrack.estimate.transport.road_blocks.PairBlocks`, with
    Dijkstra stopped at ``_LIMIT_FACTOR × gate`` when the gate is finite. A block with entries
    beyond that limit is first solved with them capped at the limit (lower bounds), which gives
    a lower bound on the EMD: ``+inf`` if it reaches the gate, the exact EMD if its plan uses no
    capped entry; otherwise the pair is solved again on its exact block.
    """

    def __init__(self, metric: RoadMetric, sig_t: list[Signature], sig_q: list[Signature],
                 pairs: IntArray, gate: float) -> None:
        self.metric = metric
        self.blocks = PairBlocks(metric, sig_t, sig_q, pairs, _LIMIT_FACTOR * gate)
        self.refined = 0

    def batch(self, pairs: IntArray, gate: float,
              deadline: Deadline) -> tuple[FloatArray, BoolArray]:
        """The pairs proven by one kernel call per source signature
        (:func:`~searchtrack.estimate.transport.pair_batch.solve_sources`): their values and
        their mask; the rest are :meth:`__call__`'s."""
        return solve_sources(self.blocks, pairs, gate * (1.0 + SLACK), deadline)

    def __call__(self, i: int, j: int, p: Signature, q: Signature, gate: float,
                 deadline: Deadline) -> tuple[float, bool | None]:
        cost = self.blocks.block(i, j)
        what = f"emd (tracker {i}, measurement {j})"
        capped = self.blocks.capped(cost)
        if capped is not None:
            low, over = capped
            if nearest_support_bound(low, p.weights, q.weights) >= gate * (1.0 + SLACK):
                return math.inf, True
            solved = pair_emd(p.weights, q.weights, low, deadline)
            value, exact = _pair_value(solved, what)
            if exact is None:
                return math.inf, None
            if not over[solved.rows, solved.cols].any():
                return value, exact
            if exact and value >= gate * (1.0 + SLACK):
                return math.inf, True
            self.refined += 1
            cost = self.blocks.exact(i, j)
        if nearest_support_bound(cost, p.weights, q.weights) >= gate * (1.0 + SLACK):
            return math.inf, True
        if np.isfinite(cost).all():
            return _pair_value(pair_emd(p.weights, q.weights, cost, deadline), what)
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
