"""All the EMD pairs of one source signature in one kernel call (thesis §4.3, Algorithm 1).

The EMD matrix of an association scan solves one transportation LP (4.3)–(4.7) per tracker–
measurement pair left standing by the gate. :class:`~.road_blocks.PairBlocks` computes the road
distances from each *source* signature to the supports of all its partners at once;
:func:`source_pairs` then solves every one of those partner pairs inside one numba call: it
slices the pair's block out of the source's distance rows, applies the nearest-support lower
bound against the gate, starts the network simplex of :mod:`.simplex_kernels` from the
least-cost basis of :mod:`.simplex_start`, pivots to optimality exactly as
:func:`~.simplex.min_cost_flow` does (chunks of pivots, potentials refreshed from the tree
before optimality is accepted), and checks the plan's marginals as
:func:`~.pair_emd.pair_emd` does.

A pair is only marked solved when the kernel proves it: its EMD is optimal on a finite block
with a checked plan, or its nearest-support bound reaches the gate. Everything else (a block
with an entry beyond the search limit or across road components, a start or pivot failure, an
unrouted remainder, a marginal beyond the check) is left to the per-pair path of the library,
which handles it with its fallbacks.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.kernel_cache import follow_callees
from searchtrack.core.kernel_threads import threads_for
from searchtrack.core.types import BoolArray, FloatArray, IntArray
from searchtrack.estimate.transport.road_blocks import PairBlocks
from searchtrack.estimate.transport.simplex_kernels import (
    OPTIMAL,
    UNBOUNDED,
    init_tree,
    pivots,
    refresh,
    work_arrays,
)
from searchtrack.estimate.transport.simplex_start import start_tree

SOLVED, FALLBACK = 1, 0  # codes of source_pairs: proven by the kernel / left to the caller

_CHUNK = 20_000  # pivots per kernel call, as in simplex.min_cost_flow
_MAX_CHUNKS = 50  # beyond this many chunks a pair is left to the per-pair path (its deadline)
_ROUNDOFF = 1e-10  # unrouted mass below this (unit masses) is round-off, as in min_cost_flow
_CHECK_RTOL = 1e-7  # the marginal check of pair_emd (solve.CHECK_RTOL)


@njit(cache=True)
def solve_pair(cost: FloatArray, supply: FloatArray, nrows: int, ncols: int,
               max_chunks: int) -> tuple[int, float]:
    """``(SOLVED, EMD)`` of the unit-mass transportation problem (``cost`` the raveled
    ``(nrows, ncols)`` matrix, finite; ``supply`` the row masses then minus the column masses),
    or ``(FALLBACK, nan)`` when the optimum is not proven with a checked plan."""
    n = nrows + ncols
    n_real = nrows * ncols
    if nrows == 0 or ncols == 0:
        return FALLBACK, math.nan
    art_cost = (cost.max() + 1.0) * n
    (art_up, parent, pred, up, depth, pi, tree_flow, first_child, next_sib, prev_sib, state,
     cursor, stack, stem) = work_arrays(n, n_real)
    empty = np.zeros(0, dtype=np.int64)
    # potentials computed from the tree by refresh need no second refresh before a clean
    # pricing pass proves the start optimal (min_cost_flow refreshes once more: same values)
    refreshed_clean = start_tree(supply, cost, nrows, ncols, art_up, parent, pred, up, depth,
                                 tree_flow, first_child, next_sib, prev_sib, state, stack)
    if refreshed_clean:
        refresh(cost, n_real, art_cost, art_up, parent, pred, up, depth, pi, first_child,
                next_sib, stack)
    else:
        state[:] = 1
        init_tree(supply, art_cost, art_up, parent, pred, up, depth, pi, tree_flow,
                  first_child, next_sib, prev_sib, n_real)
    calls = 0
    while True:
        if calls >= max_chunks:
            return FALLBACK, math.nan
        done, code = pivots(_CHUNK, empty, empty, cost, ncols, nrows, n_real, art_up, state,
                            parent, pred, up, depth, pi, tree_flow, first_child, next_sib,
                            prev_sib, cursor, stack, stem)
        calls += 1
        if code == UNBOUNDED:
            return FALLBACK, math.nan
        if code == OPTIMAL:
            if done == 0 and refreshed_clean:
                break
            refresh(cost, n_real, art_cost, art_up, parent, pred, up, depth, pi,
                    first_child, next_sib, stack)
            refreshed_clean = True
            continue
        refreshed_clean = False
    art_out, art_in = 0.0, 0.0
    out = np.zeros(nrows)
    into = np.zeros(ncols)
    value = 0.0
    for u in range(n):
        e = pred[u]
        f = tree_flow[u]
        if e >= n_real:
            if art_up[e - n_real]:
                art_out += f
            else:
                art_in += f
        elif f > 0.0:
            i = e // ncols
            out[i] += f
            into[e - i * ncols] += f
            value += cost[e] * f
    if max(art_out, art_in) > _ROUNDOFF:
        return FALLBACK, math.nan  # not routed: the per-pair path decides
    worst = 0.0
    for i in range(nrows):
        worst = max(worst, abs(out[i] - supply[i]))
    for j in range(ncols):
        worst = max(worst, abs(into[j] + supply[nrows + j]))
    if not worst <= _CHECK_RTOL:
        return FALLBACK, math.nan
    return SOLVED, value


@njit(cache=True)
def _bound(cost: FloatArray, p: FloatArray, q: FloatArray, nrows: int, ncols: int) -> float:
    """``max(Σ_i p_i min_j d_ij, Σ_j q_j min_i d_ij)``: the nearest-support lower bound."""
    col_min = np.full(ncols, np.inf)
    by_rows = 0.0
    for i in range(nrows):
        row_min = np.inf
        for j in range(ncols):
            c = cost[i * ncols + j]
            row_min = min(row_min, c)
            col_min[j] = min(col_min[j], c)
        by_rows += p[i] * row_min
    by_cols = 0.0
    for j in range(ncols):
        by_cols += q[j] * col_min[j]
    return max(by_rows, by_cols)


@njit(cache=True)
def _partner(
    dist: FloatArray, flip: bool, src_w: FloatArray, m: int, nodes_all: IntArray,
    w_all: FloatArray, ptr_all: IntArray, targets: IntArray, threshold: float, max_chunks: int,
) -> tuple[int, float]:
    """:func:`source_pairs` for its partner signature ``m``."""
    s = dist.shape[0]
    a, b = ptr_all[m], ptr_all[m + 1]
    cols = np.searchsorted(targets, nodes_all[a:b])
    t = b - a
    if flip:
        nrows, ncols = t, s
    else:
        nrows, ncols = s, t
    cost = np.empty(nrows * ncols)
    finite = True
    for i in range(nrows):
        for j in range(ncols):
            c = dist[j, cols[i]] if flip else dist[i, cols[j]]
            finite = finite and math.isfinite(c)
            cost[i * ncols + j] = c
    if not finite:
        return FALLBACK, math.nan  # beyond the search limit or across components
    supply = np.empty(nrows + ncols)
    if flip:
        supply[:nrows] = w_all[a:b]
        supply[nrows:] = -src_w
    else:
        supply[:nrows] = src_w
        supply[nrows:] = -w_all[a:b]
    if threshold < math.inf and _bound(cost, supply[:nrows], -supply[nrows:], nrows,
                                       ncols) >= threshold:
        return SOLVED, math.inf
    return solve_pair(cost, supply, nrows, ncols, max_chunks)


@njit(cache=True, parallel=True)
def source_pairs(
    dist: FloatArray, flip: bool, src_w: FloatArray, partners: IntArray, nodes_all: IntArray,
    w_all: FloatArray, ptr_all: IntArray, targets: IntArray, threshold: float,
    max_chunks: int, values: FloatArray, codes: NDArray[np.int8],
) -> None:
    """Solve the pairs of one source signature, partners in parallel (each pair on its own).

    ``dist`` is the ``(|S|, len(targets))`` block of the source's support against the sorted
    ``targets``; partner ``partners[k]`` has support ``nodes_all[ptr_all[m]:ptr_all[m + 1]]``
    and normalised weights ``w_all`` there (``m = partners[k]``), the source the normalised
    ``src_w``. Without ``flip`` the source is the tracker (the rows of the LP), with it the
    measurement (the columns). ``values[k]`` is the EMD (or ``inf`` when the nearest-support
    bound reaches ``threshold``) where ``codes[k] == SOLVED``; ``FALLBACK`` pairs (a block with
    an ``inf`` entry: beyond the search limit or across components; an unproven solve) are
    the caller's.
    """
    for k in prange(partners.shape[0]):
        code, value = _partner(dist, flip, src_w, partners[k], nodes_all, w_all, ptr_all,
                               targets, threshold, max_chunks)
        codes[k] = code
        values[k] = value


_PAIR_WORK = 1 << 14
"""Distance-block entries (pairs × block size) from which a source's pairs are solved on all of
numba's threads: each pair's simplex sweeps its block many times, so far fewer elements than
:data:`~searchtrack.core.kernel_threads.PARALLEL_WORK` pay for the threads."""


def solve_sources(blocks: PairBlocks, pairs: IntArray, threshold: float,
                  deadline: Deadline) -> tuple[FloatArray, BoolArray]:
    """The pairs ``pairs`` (rows ``(tracker, measurement)``) that :func:`source_pairs` proves,
    one call per source signature of ``blocks`` while ``deadline`` lasts: their values (EMD, or
    ``inf`` where the nearest-support bound reaches ``threshold``) and the mask of them."""
    values = np.full(len(pairs), math.nan)
    done = np.zeros(len(pairs), dtype=bool)
    if len(pairs) == 0:
        return values, done
    src_col, dst_col = (1, 0) if blocks.from_measurements else (0, 1)
    dst = blocks.dst_sigs
    nodes_all, w_all, ptr_all = packed([s.nodes for s in dst], [s.weights for s in dst])
    order = np.argsort(pairs[:, src_col], kind="stable")
    keys = pairs[order, src_col]
    starts = np.flatnonzero(np.r_[True, keys[1:] != keys[:-1]])
    for a, b in zip(starts.tolist(), [*starts[1:].tolist(), len(keys)], strict=True):
        if deadline.expired():
            break
        rows = order[a:b]
        k = int(keys[a])
        targets, dist = blocks.source_block(k)
        got = np.empty(b - a)
        codes = np.empty(b - a, dtype=np.int8)
        with threads_for((b - a) * dist.size, least=_PAIR_WORK):
            source_pairs(np.ascontiguousarray(dist, dtype=np.float64), blocks.from_measurements,
                         normalised(blocks.src_sigs[k].weights),
                         np.ascontiguousarray(pairs[rows, dst_col], dtype=np.int64), nodes_all,
                         w_all, ptr_all, np.ascontiguousarray(targets, dtype=np.int64),
                         float(threshold), _MAX_CHUNKS, got, codes)
        ok = codes == SOLVED
        values[rows[ok]] = got[ok]
        done[rows[ok]] = True
    return values, done


def normalised(weights: FloatArray) -> FloatArray:
    """``weights`` scaled to unit mass as :func:`~.pair_emd.pair_emd` scales them."""
    out: FloatArray = weights / float(weights.sum())
    return out


def packed(nodes: list[IntArray], weights: list[FloatArray]) -> tuple[IntArray, FloatArray,
                                                                       IntArray]:
    """Signatures' nodes and normalised weights, concatenated, with their offsets."""
    sizes = np.array([x.size for x in nodes], dtype=np.int64)
    ptr = np.zeros(sizes.size + 1, dtype=np.int64)
    np.cumsum(sizes, out=ptr[1:])
    if not nodes:
        return np.zeros(0, np.int64), np.zeros(0), ptr
    return (np.concatenate(nodes).astype(np.int64),
            np.concatenate([normalised(w) for w in weights]), ptr)


def warm_up() -> None:
    """Compile (or load) :func:`source_pairs` on a 1 × 2 problem."""
    values = np.empty(1)
    codes = np.empty(1, dtype=np.int8)
    source_pairs(np.array([[1.0, 2.0]]), False, np.array([1.0]), np.zeros(1, np.int64),
                 np.array([3, 4], np.int64), np.array([0.5, 0.5]), np.array([0, 2], np.int64),
                 np.array([3, 4], np.int64), math.inf, _MAX_CHUNKS, values, codes)
    source_pairs(np.array([[1.0, 2.0]]), True, np.array([1.0]), np.zeros(1, np.int64),
                 np.array([3, 4], np.int64), np.array([0.5, 0.5]), np.array([0, 2], np.int64),
                 np.array([3, 4], np.int64), math.inf, _MAX_CHUNKS, values, codes)


follow_callees(__name__, globals())
