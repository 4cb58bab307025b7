"""Numba kernel of :mod:`searchtrack.estimate.transport.road_blocks`: bounded Dijkstra to targets.

One Dijkstra per source on a CSR graph (``indptr``, ``indices``, ``lengths``), with a binary heap
and lazy deletion. A search stops at the distance ``limit`` (nodes farther away are never
settled) or as soon as every target is settled, so a source near its targets explores only its
neighbourhood. Per-node scratch arrays are stamped with the source's index instead of being
cleared, so a source costs only what it explores, not the size of the graph.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from searchtrack.core.types import FloatArray, IntArray


@njit(cache=True, inline="always")
def _push(heap_d: FloatArray, heap_v: IntArray, size: int, d: float, v: int) -> int:
    i = size
    while i > 0:
        parent = (i - 1) >> 1
        if heap_d[parent] <= d:
            break
        heap_d[i], heap_v[i] = heap_d[parent], heap_v[parent]
        i = parent
    heap_d[i], heap_v[i] = d, v
    return size + 1


@njit(cache=True, inline="always")
def _pop(heap_d: FloatArray, heap_v: IntArray, size: int) -> int:
    """Remove the root (the caller read it first); the new size."""
    size -= 1
    d, v = heap_d[size], heap_v[size]
    i = 0
    while True:
        child = 2 * i + 1
        if child >= size:
            break
        if child + 1 < size and heap_d[child + 1] < heap_d[child]:
            child += 1
        if heap_d[child] >= d:
            break
        heap_d[i], heap_v[i] = heap_d[child], heap_v[child]
        i = child
    heap_d[i], heap_v[i] = d, v
    return size


@njit(cache=True)
def bounded_rows(indptr: IntArray, indices: IntArray, lengths: FloatArray, sources: IntArray,
                 target_col: IntArray, n_targets: int, limit: float, out: FloatArray) -> int:
    """Write ``out[s, target_col[v]] = d(sources[s], v)`` for every target ``v`` within ``limit``.

    ``target_col`` maps a node to its column in ``out`` (−1: not a target; the ``n_targets``
    columns are distinct). Entries of targets beyond ``limit`` (or in another component) are
    left as they are: the caller fills ``out`` with ``inf`` first. Returns the number of nodes
    settled over all sources.
    """
    n = indptr.size - 1
    dist = np.empty(n)
    seen = np.full(n, -1, dtype=np.int64)
    settled = np.full(n, -1, dtype=np.int64)
    heap_d = np.empty(indices.size + 1)
    heap_v = np.empty(indices.size + 1, dtype=np.int64)
    work = 0
    for s in range(sources.size):
        src = sources[s]
        dist[src] = 0.0
        seen[src] = s
        size = _push(heap_d, heap_v, 0, 0.0, src)
        found = 0
        while size > 0:
            d, v = heap_d[0], heap_v[0]
            size = _pop(heap_d, heap_v, size)
            if settled[v] == s:
                continue
            settled[v] = s
            work += 1
            col = target_col[v]
            if col >= 0:
                out[s, col] = d
                found += 1
                if found == n_targets:
                    break
            for k in range(indptr[v], indptr[v + 1]):
                w = indices[k]
                nd = d + lengths[k]
                if nd <= limit and (seen[w] != s or nd < dist[w]):
                    dist[w] = nd
                    seen[w] = s
                    size = _push(heap_d, heap_v, size, nd, w)
    return work


@njit(cache=True, parallel=True)
def table_rows(
    table: FloatArray, end_a: IntArray, end_b: IntArray, off_a: FloatArray, off_b: FloatArray,
    chain: IntArray, sources: IntArray, targets: IntArray, out: FloatArray,
) -> None:
    """``out[s, t]``: the road distance from ``sources[s]`` to ``targets[t]`` through the
    junction table ``table`` (the least of the four end-to-end sums, or the distance along a
    shared chain), summed and compared in the order of
    :meth:`~searchtrack.models.road_metric.SourceDistances.to`."""
    n_t = targets.shape[0]
    t_a, t_b = np.empty(n_t, dtype=np.int64), np.empty(n_t, dtype=np.int64)
    t_ao, t_bo = np.empty(n_t), np.empty(n_t)
    t_chain = np.empty(n_t, dtype=np.int64)
    for t in range(n_t):  # the targets' ends, gathered once for all sources
        v = targets[t]
        t_a[t], t_b[t], t_ao[t], t_bo[t], t_chain[t] = end_a[v], end_b[v], off_a[v], off_b[v], \
            chain[v]
    for s in prange(sources.shape[0]):  # rows in parallel
        u = sources[s]
        ra, rb, sa, sb, cs = end_a[u], end_b[u], off_a[u], off_b[u], chain[u]
        row_a, row_b = table[ra], table[rb]
        for t in range(n_t):
            ta, tb, tao, tbo = t_a[t], t_b[t], t_ao[t], t_bo[t]
            d = sa + row_a[ta] + tao
            d = min(d, sa + row_a[tb] + tbo)
            d = min(d, sb + row_b[ta] + tao)
            d = min(d, sb + row_b[tb] + tbo)
            if cs >= 0 and cs == t_chain[t]:
                d = min(d, abs(sa - tao))
            out[s, t] = d
