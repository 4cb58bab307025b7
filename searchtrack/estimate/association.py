"""The association seam: which tracker, if any, each position measurement belongs to.

:class:`Association` is the answer and :class:`Associator` the role
(:class:`~searchtrack.estimate.scan.ScanUpdater` is given one). Pairing trackers with
measurements on a cost matrix is a solver family: an :class:`AssociationProblem` (a
trackers × measurements cost matrix and a gate) solved by name from :data:`BACKENDS`:

- ``greedy``: Algorithm 1 (§4.3), the global minimum first while it is below the gate;
- ``optimal``: the exact gated assignment, a linear assignment problem
  (:func:`scipy.optimize.linear_sum_assignment`);
- ``auto``: greedy at once, then the exact solver within the time left
  (:func:`~searchtrack.core.registry.heuristic_then_exact`).

Every backend maximises the *gated saving* ``Σ (gate − c_ij)`` over its pairs, the cost saved
against leaving each paired measurement unassociated at the gate; equivalently it minimises
``Σ (c_ij − gate)`` (:func:`gated_objective`). The EMD costs of the thesis are built by
:class:`~searchtrack.estimate.emd_association.EMDAssociator`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import linear_sum_assignment

from searchtrack.core.checks import positive
from searchtrack.core.deadline import Deadline
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.registry import Backend, Registry, heuristic_then_exact
from searchtrack.core.result import Result, Status
from searchtrack.core.types import FloatArray
from searchtrack.estimate.node_tracker import TrackerBank

Pairs = tuple[tuple[int, int], ...]


@dataclass(frozen=True)
class Association:
    """One-to-one pairs ``(tracker index, measurement index)``; the rest go unassociated.

    Indices refer to the bank's tracker order and the rows of the measurement densities.
    """

    pairs: Pairs = ()

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


def _cost_matrix(costs: ArrayLike) -> FloatArray:
    """``costs`` as a read-only 2-D float copy, finite or ``+inf`` (never associable)."""
    try:
        c = np.array(costs, dtype=np.float64, copy=True)
    except (TypeError, ValueError):
        raise InvalidInputError("costs", costs, "must be a 2-D array of numbers") from None
    if c.ndim != 2:
        raise InvalidInputError("costs", costs, "must be a 2-D (trackers × measurements) array")
    if np.isnan(c).any() or np.isneginf(c).any():
        raise InvalidInputError("costs", costs, "must not contain NaN or -inf")
    c.setflags(write=False)
    return c


@dataclass(frozen=True, eq=False)
class AssociationProblem:
    """Gated one-to-one pairing of trackers with measurements (§4.3).

    Parameters
    ----------
    costs
        ``(k, q)`` cost of pairing tracker ``i`` with measurement ``j`` (the EMD in metres for
        Algorithm 1); ``+inf`` for a pair that may never associate. Stored as a read-only copy.
    gate_m
        The gate ``𝓔`` (300 m in the thesis): only pairs with ``c_ij < gate_m`` may associate.
    """

    costs: FloatArray
    gate_m: float = 300.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "costs", _cost_matrix(self.costs))
        object.__setattr__(self, "gate_m", positive("gate_m", self.gate_m))

    @property
    def shape(self) -> tuple[int, int]:
        """``(k, q)``: trackers × measurements."""
        return (int(self.costs.shape[0]), int(self.costs.shape[1]))

    def saving(self, pairs: Pairs) -> float:
        """The gated saving ``Σ (gate − c_ij)`` of ``pairs``, the objective every backend
        maximises (positive for pairs under the gate)."""
        return float(sum(self.gate_m - self.costs[i, j] for i, j in pairs))


def greedy_pairs(costs: ArrayLike, gate_m: float) -> Pairs:
    """Algorithm 1's greedy gated matching on a ``(k, q)`` cost matrix, in the order chosen.

    Repeatedly take the smallest entry while it is ``< gate_m``, then remove its row and column.
    Ties go to the lowest tracker index, then the lowest measurement index.
    """
    return _greedy(_cost_matrix(costs), positive("gate_m", gate_m))


def _greedy(costs: FloatArray, gate: float) -> Pairs:
    """:func:`greedy_pairs` on a checked cost matrix (left unchanged) and gate."""
    c = np.array(costs, copy=True)
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
    return _optimal(_cost_matrix(costs), positive("gate_m", gate_m))


def _optimal(c: FloatArray, gate: float) -> Pairs:
    """:func:`optimal_pairs` on a checked cost matrix and gate."""
    if c.size == 0:
        return ()
    rows, cols = linear_sum_assignment(np.minimum(c - gate, 0.0))
    keep = c[rows, cols] < gate
    return tuple(sorted(zip(rows[keep].tolist(), cols[keep].tolist(), strict=True)))


def gated_objective(costs: ArrayLike, pairs: Pairs, gate_m: float) -> float:
    """``Σ (c_ij − gate)`` over ``pairs``: the objective :func:`optimal_pairs` minimises."""
    c = _cost_matrix(costs)
    gate = positive("gate_m", gate_m)
    return float(sum(c[i, j] - gate for i, j in pairs))


def solve_greedy(problem: AssociationProblem, *, time_limit_s: float,
                 seed: int) -> Result[Association]:
    """Algorithm 1 (:func:`greedy_pairs`): ``FEASIBLE``, no bound. Deterministic and
    ``O(min(k, q) · k q)``; ``time_limit_s`` and ``seed`` are not needed."""
    deadline = Deadline(time_limit_s)
    pairs = _greedy(problem.costs, problem.gate_m)
    return Result(Status.FEASIBLE, problem.saving(pairs), None, deadline.elapsed(), "greedy",
                  Association(pairs), message=f"{len(pairs)} pairs, global minimum first")


def solve_optimal(problem: AssociationProblem, *, time_limit_s: float,
                  seed: int) -> Result[Association]:
    """The exact gated assignment (:func:`optimal_pairs`): ``OPTIMAL``, bound = objective.
    A linear assignment in ``O((k + q)³)``; ``time_limit_s`` and ``seed`` are not needed."""
    deadline = Deadline(time_limit_s)
    pairs = _optimal(problem.costs, problem.gate_m)
    saving = problem.saving(pairs)
    return Result(Status.OPTIMAL, saving, saving, deadline.elapsed(), "optimal",
                  Association(pairs), message=f"{len(pairs)} pairs, linear assignment")


def _exact_stage(problem: AssociationProblem, first: Result[Association], limit_s: float,
                 seed: int) -> Result[Association]:
    return solve_optimal(problem, time_limit_s=limit_s, seed=seed)


def solve_auto(problem: AssociationProblem, *, time_limit_s: float,
               seed: int) -> Result[Association]:
    """Greedy at once, then the exact assignment within the time left; the better plan wins
    (the exact one on ties), ``OPTIMAL`` once the exact solve has run."""
    return heuristic_then_exact(problem, solve_greedy, _exact_stage, time_limit_s=time_limit_s,
                                seed=seed, heuristic_limit_s=time_limit_s)


def answer_problems(problem: AssociationProblem, result: Result[Association],
                    seed: int = 0) -> list[str]:
    """The independent check of an association: every pair names an existing tracker and
    measurement, each once, with a cost under the gate; the objective is the pairs' gated
    saving ``Σ (gate − c_ij)`` summed here from the cost matrix, and never above a claimed
    bound."""
    del seed  # the check draws nothing
    assert result.plan is not None
    k, q = problem.shape
    problems: list[str] = []
    seen_t: set[int] = set()
    seen_q: set[int] = set()
    saving = 0.0
    for t, j in result.plan.pairs:
        if not (0 <= t < k and 0 <= j < q):
            problems.append(f"pair ({t}, {j}) outside {k} trackers x {q} measurements")
            continue
        if t in seen_t or j in seen_q:
            problems.append(f"pair ({t}, {j}) reuses a tracker or a measurement")
        seen_t.add(t)
        seen_q.add(j)
        cost = float(problem.costs[t, j])
        if not cost < problem.gate_m:
            problems.append(f"pair ({t}, {j}) costs {cost:g}, not under the gate "
                            f"{problem.gate_m:g}")
        saving += problem.gate_m - cost
    tol = 1e-9 * (1.0 + abs(saving))
    if not problems and result.objective is not None and abs(result.objective - saving) > tol:
        problems.append(f"reported saving {result.objective} but the pairs save {saving}")
    if result.objective is not None and result.bound is not None and \
            result.objective > result.bound + tol:
        problems.append(f"saving {result.objective} exceeds the claimed bound {result.bound}")
    return problems


#: The association backends by name: ``BACKENDS.get(name).solve(problem, ...)``.
BACKENDS: Registry[AssociationProblem, Association] = Registry("association",
                                                                validator=answer_problems)
BACKENDS.register(Backend("greedy", solve_greedy, False,
                          "Algorithm 1 (§4.3): the global minimum under the gate first"))
BACKENDS.register(Backend("optimal", solve_optimal, True,
                          "the gated assignment, exact by linear_sum_assignment"))
BACKENDS.register(Backend("auto", solve_auto, True,
                          "greedy at once, then the exact assignment in the time left"))


def solve(problem: AssociationProblem, *, backend: str = "greedy", time_limit_s: float = 1.0,
          seed: int = 0) -> Result[Association]:
    """Pair the trackers and measurements of ``problem`` with the named backend.

    ``objective`` is the gated saving ``Σ (gate − c_ij)`` (maximised, ≥ 0); ``plan`` the
    :class:`Association`.

    Raises
    ------
    InvalidInputError
        Unknown backend, a bad time limit or seed.
    """
    return BACKENDS.solve(backend, problem, time_limit_s=time_limit_s, seed=seed)
