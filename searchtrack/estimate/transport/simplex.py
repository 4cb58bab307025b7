"""Primal network simplex for uncapacitated min-cost flow with real-valued supplies and costs.

The exact fast path behind :func:`~searchtrack.estimate.transport.emd` and
:func:`~searchtrack.estimate.transport.emd_on_graph`. It is the textbook method (Ahuja, Magnanti and
Orlin, *Network Flows*, ch. 11; the same algorithm as LEMON's and POT's ``ot.emd``):

* a spanning tree basis rooted at an artificial node, started from one artificial arc per node
  (big-M cost ``(max cost + 1)·N`` for arcs that carry demand, so they leave whenever the problem
  is feasible);
* block-search pricing (blocks of √A arcs) with a tolerance relative to the magnitudes involved;
* strongly feasible trees (the last blocking arc of the cycle leaves), so degenerate pivots
  cannot cycle;
* the tree kept as parent / child lists with depths; a pivot re-roots the cut subtree and shifts
  its potentials in one pass over it.

Arcs are uncapacitated, so every non-tree arc carries zero flow and flows live on tree arcs only
(``tree_flow[v]`` is the flow on ``pred[v]``). Arcs are either explicit (``tail``/``head``
arrays) or, for a transportation problem, implicit: arc ``e`` of an ``m × n`` cost matrix joins
row ``e // n`` to node ``m + e % n``, so the cost matrix is used in place.

The solve runs in chunks of pivots so that the caller can honour a wall-clock deadline.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import Literal

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.transport import dijkstra_kernels
from searchtrack.estimate.transport import simplex_kernels as kernels
from searchtrack.estimate.transport.simplex_start import start_tree

log = logging.getLogger("searchtrack.estimate.transport")


_CHUNK = 20_000  # pivots between deadline checks
_ROUNDOFF = 1e-10  # unrouted mass below this fraction of the mass scale is round-off

NativeStatus = Literal["optimal", "infeasible", "unbounded", "time_limit"]

KERNEL_SET = "simplex"
"""The ``searchtrack warm-up`` name of these kernels, listed by every backend that runs them."""

_WARM = [False]


def warm_up() -> None:
    """Compile (or load from numba's cache) the simplex kernels, the bounded Dijkstra of
    :mod:`~searchtrack.estimate.transport.road_blocks` and the signature truncation of
    :mod:`~searchtrack.estimate.signatures`, once per process.

    Callers run it before starting their clock, so a time limit measures solving, not
    just-in-time compilation (seconds on a cold cache).
    """
    if _WARM[0]:
        return
    started = time.perf_counter()
    supply = np.array([1.0, 0.0, -1.0])
    cost = np.array([1.0, 2.0, 1.0, 3.0])
    tail = np.array([0, 0, 1, 2], dtype=np.int64)
    head = np.array([1, 2, 2, 0], dtype=np.int64)
    min_cost_flow(supply, cost, Deadline(math.inf), tail=tail, head=head)
    min_cost_flow(np.array([0.5, 0.5, -1.0]), np.array([1.0, 2.0]), Deadline(math.inf), ncols=1)
    min_cost_flow(np.array([0.5, 0.5, -1.0]), np.array([1.0, 2.0]), Deadline(math.inf), ncols=1,
                  least_cost_start=True)
    out = np.full((1, 1), math.inf)  # the bounded Dijkstra of the EMD matrix's road blocks
    two = np.array([1, 0], dtype=np.int64)  # nodes 0 — 1, one edge of 1 m
    dijkstra_kernels.bounded_rows(np.array([0, 1, 2], dtype=np.int64), two, np.ones(2),
                                  two[1:], two - 1, 1, 5.0, out)
    dijkstra_kernels.table_rows(np.zeros((1, 1)), two * 0, two * 0, np.ones(2), np.ones(2),
                                two, two, two, np.empty((2, 2)))
    from searchtrack.estimate import signatures  # the truncation of the EMD matrix's rows
    from searchtrack.estimate.transport import pair_batch  # the EMD matrix's per-source pairs

    pair_batch.warm_up()

    signatures.warm_up()
    _WARM[0] = True
    log.info("network simplex kernels ready in %.2f s", time.perf_counter() - started)


@dataclass(frozen=True)
class FlowSolution:
    """Raw outcome of :func:`min_cost_flow`: positive flows on real arcs and the native status."""

    status: NativeStatus
    arcs: IntArray  # real arc indices with positive flow
    amounts: FloatArray  # their flows
    artificial_flow: float  # mass not routed by real arcs (through the artificial root)
    pivots: int
    routed: bool  # artificial_flow is round-off only: the real flow is feasible


def min_cost_flow(
    supply: FloatArray,
    cost: FloatArray,
    deadline: Deadline,
    *,
    tail: IntArray | None = None,
    head: IntArray | None = None,
    ncols: int = 0,
    mass_scale: float | None = None,
    least_cost_start: bool = False,
) -> FlowSolution:
    """Minimise ``cost @ flow`` over flows ≥ 0 meeting ``supply`` (> 0 source, < 0 sink).

    Either explicit arcs ``tail[e] -> head[e]`` with ``cost[e]``, or, with ``ncols > 0``, the
    complete bipartite graph of a transportation problem: ``cost`` is the raveled
    ``(len(supply) - ncols, ncols)`` matrix, rows are the first nodes and columns the last.
    ``supply`` should sum to zero; what cannot be routed is reported as ``artificial_flow``,
    and up to ``1e-10 · mass_scale`` of it (default: the mass to move) counts as round-off.
    Costs must be finite and non-negative (the caller checks). With ``least_cost_start`` a
    transportation problem starts from the least-cost basis of
    :func:`~.simplex_start.start_tree` (a feasible flow from the outset), else from one
    artificial arc per node.
    """
    n = supply.shape[0]
    n_real = cost.shape[0]
    nrows = n - ncols if ncols > 0 else 0
    empty = np.zeros(0, dtype=np.int64)
    tail_a = empty if tail is None else tail
    head_a = empty if head is None else head
    max_cost = float(cost.max()) if n_real else 0.0
    art_cost = (max_cost + 1.0) * max(n, 1)
    (art_up, parent, pred, up, depth, pi, tree_flow, first_child, next_sib, prev_sib, state,
     cursor, stack, stem) = kernels.work_arrays(n, n_real)
    if ncols > 0 and n_real > 0 and least_cost_start and start_tree(
            supply, cost, nrows, ncols, art_up, parent, pred, up, depth, tree_flow,
            first_child, next_sib, prev_sib, state, stack):
        kernels.refresh(cost, n_real, art_cost, art_up, parent, pred, up, depth, pi,
                        first_child, next_sib, stack)
    else:
        state[:] = 1
        kernels.init_tree(supply, art_cost, art_up, parent, pred, up, depth, pi, tree_flow,
                          first_child, next_sib, prev_sib, n_real)
    tree = (parent, pred, up, depth, pi, tree_flow, first_child, next_sib, prev_sib)
    pivots = 0
    refreshed_clean = False
    native: NativeStatus = "optimal" if n_real == 0 else "time_limit"
    while n_real > 0 and not deadline.expired():
        done, code = kernels.pivots(_CHUNK, tail_a, head_a, cost, ncols, nrows, n_real, art_up,
                                    state, *tree, cursor, stack, stem)
        pivots += done
        if code == kernels.UNBOUNDED:
            native = "unbounded"
            break
        if code == kernels.OPTIMAL:
            if done == 0 and refreshed_clean:
                native = "optimal"
                break
            # recompute the potentials exactly from the tree, then price once more
            kernels.refresh(cost, n_real, art_cost, art_up, parent, pred, up, depth, pi,
                            first_child, next_sib, stack)
            refreshed_clean = True
            continue
        refreshed_clean = False
    arc_of = pred[:n]
    real = (arc_of < n_real) & (tree_flow[:n] > 0.0)
    # an unrouted unit rides two artificial arcs (source -> root -> sink): count it once, as
    # the larger of the flows into and out of the root (they differ if supply does not sum to 0)
    on_artificial = np.where(arc_of >= n_real, tree_flow[:n], 0.0)
    artificial_flow = max(float(on_artificial[art_up == 1].sum()),
                          float(on_artificial[art_up == 0].sum()))
    scale = float(np.abs(supply).sum()) / 2.0 if mass_scale is None else mass_scale
    routed = artificial_flow <= _ROUNDOFF * scale
    if native == "optimal" and not routed:
        native = "infeasible"
    log.debug("network simplex: %s after %d pivots (%d nodes, %d arcs)", native, pivots, n,
              n_real)
    return FlowSolution(native, arc_of[real].copy(), tree_flow[:n][real].copy(), artificial_flow,
                        pivots, routed)
