"""A starting basis for the network simplex on a transportation problem (thesis §4.3, (4.3)–(4.7)).

The network simplex of :mod:`~searchtrack.estimate.transport.simplex` starts, in general, from
one artificial arc per node, and every unit of mass must then be moved onto real arcs by
pivots. For the complete bipartite graph of an EMD pair, :func:`start_tree` builds a feasible
spanning tree of real arcs instead, by the least-cost rule of the transportation method: arcs
in increasing cost order (to within a bucket of a counting sort, linear in the arcs), each
given as much mass as its row and column still hold, and one line (row or column) struck out
per arc, so that the arcs form a forest with one unstruck line in each tree; lines a tie left
unstruck are joined by zero-flow arcs into one spanning tree of ``m + n − 1`` arcs.

The tree hangs from the artificial root by the artificial arc of row 0, which carries only the
round-off by which the two masses differ. Flows are recomputed from the tree and the supplies
(not taken from the greedy's remainders), potentials by
:func:`~searchtrack.estimate.transport.simplex_kernels.refresh`; the simplex then proceeds from
this basis to the same optimum.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.transport.simplex_kernels import attach


@njit(cache=True)
def _least_cost_arcs(supply: FloatArray, cost: FloatArray, nrows: int, ncols: int) -> IntArray:
    """The ``nrows + ncols − 1`` basic arcs of the least-cost rule (arc ``i · ncols + j``),
    arcs ranked by a counting sort into ``4 (nrows + ncols)`` equal cost buckets (index order
    within a bucket): any order gives a basis, a cheaper-first one a better one."""
    left = supply.copy()
    for j in range(ncols):
        left[nrows + j] = -left[nrows + j]
    struck = np.zeros(nrows + ncols, dtype=np.bool_)
    last = np.full(nrows + ncols, -1, dtype=np.int64)  # the other end of a line's latest arc
    lines = nrows + ncols
    arcs = np.empty(lines - 1, dtype=np.int64)
    k = 0
    n_arcs = cost.shape[0]
    low, high = np.inf, -np.inf
    for e in range(n_arcs):
        low = min(low, cost[e])
        high = max(high, cost[e])
    span = high - low
    buckets = 4 * lines
    scale = (buckets - 1) / span if span > 0.0 else 0.0
    count = np.zeros(buckets + 1, dtype=np.int64)
    bucket = np.empty(n_arcs, dtype=np.int64)
    for e in range(n_arcs):
        b = int((cost[e] - low) * scale)
        bucket[e] = b
        count[b + 1] += 1
    for b in range(buckets):
        count[b + 1] += count[b]
    # cost buckets in order, arcs in index order within one; ends kept apart (no division)
    rank_i = np.empty(n_arcs, dtype=np.int32)
    rank_j = np.empty(n_arcs, dtype=np.int32)
    e = 0
    for i in range(nrows):
        for j in range(ncols):
            b = bucket[e]
            rank_i[count[b]] = i
            rank_j[count[b]] = j
            count[b] += 1
            e += 1
    for r in range(n_arcs):
        if k == lines - 1:
            break
        i = int(rank_i[r])
        j = nrows + int(rank_j[r])
        e = i * ncols + int(rank_j[r])
        if struck[i] or struck[j]:
            continue
        arcs[k] = e
        k += 1
        last[i], last[j] = j, i
        if left[i] <= left[j]:
            left[j] -= left[i]
            left[i] = 0.0
            struck[i] = True
        else:
            left[i] -= left[j]
            left[j] = 0.0
            struck[j] = True
    # lines left over (all rows or all columns, emptied by ties) are joined by zero-flow arcs
    # to the other end of the first one's latest arc: each joins two components of the forest
    anchor, first = -1, -1
    for u in range(lines):
        if struck[u] or k == lines - 1:
            continue
        if anchor < 0:
            anchor, first = int(last[u]), u
            if anchor < 0:
                break
        elif (u < nrows) != (first < nrows):
            break  # not a tie's leftovers: the caller starts from the artificial arcs
        elif u < nrows:
            arcs[k] = u * ncols + anchor - nrows
            k += 1
        else:
            arcs[k] = anchor * ncols + u - nrows
            k += 1
    return arcs[:k]


@njit(cache=True)
def start_tree(
    supply: FloatArray, cost: FloatArray, nrows: int, ncols: int, art_up: NDArray[np.int8],
    parent: IntArray, pred: IntArray, up: NDArray[np.int8],
    depth: IntArray, tree_flow: FloatArray, first_child: IntArray, next_sib: IntArray,
    prev_sib: IntArray, state: NDArray[np.int8], stack: IntArray,
) -> bool:
    """Set the tree arrays of :mod:`~searchtrack.estimate.transport.simplex_kernels` to the
    least-cost basis (module docstring); ``False`` (arrays unspecified) if its arcs do not
    span the nodes, when the caller starts from the artificial arcs instead."""
    n = nrows + ncols
    n_real = cost.shape[0]
    root = n
    arcs = _least_cost_arcs(supply, cost, nrows, ncols)
    if arcs.shape[0] != n - 1:
        return False
    # adjacency of the tree arcs
    degree = np.zeros(n + 1, dtype=np.int64)
    for e in arcs:
        i = e // ncols
        degree[i + 1] += 1
        degree[nrows + e - i * ncols + 1] += 1
    start = np.cumsum(degree)
    fill = start[:-1].copy()
    nbr_arc = np.empty(2 * (n - 1), dtype=np.int64)
    for e in arcs:
        i = e // ncols
        j = nrows + e - i * ncols
        nbr_arc[fill[i]] = e
        fill[i] += 1
        nbr_arc[fill[j]] = e
        fill[j] += 1
    for u in range(n + 1):
        first_child[u] = -1
        next_sib[u] = -1
        prev_sib[u] = -1
        parent[u] = -1
    for u in range(n):
        art_up[u] = 1 if supply[u] >= 0.0 else 0
    parent[root] = -1
    pred[root] = -1
    depth[root] = 0
    # depth-first from row 0, hung from the root; order[] records the visit order
    order = np.empty(n, dtype=np.int64)
    seen = 0
    parent[0] = root
    depth[0] = 1
    top = 0
    stack[top] = 0
    top += 1
    while top > 0:
        top -= 1
        x = stack[top]
        order[seen] = x
        seen += 1
        for k in range(start[x], start[x + 1]):
            e = nbr_arc[k]
            i = e // ncols
            y = nrows + e - i * ncols if x == i else i
            if y == parent[x] and pred[x] == e:
                continue
            if parent[y] >= 0:
                return False  # a cycle: not a tree
            parent[y] = x
            pred[y] = e
            up[y] = 1 if y == i else 0  # the arc runs row -> column
            depth[y] = depth[x] + 1
            stack[top] = y
            top += 1
    if seen != n:
        return False
    # flows from the leaves up: the net supply of a subtree crosses its top arc
    net = supply[:n].copy()
    for k in range(n - 1, 0, -1):
        y = order[k]
        x = parent[y]
        net[x] += net[y]
        flow = net[y] if up[y] else -net[y]
        tree_flow[y] = flow if flow > 0.0 else 0.0
    if net[0] >= 0.0:  # row 0's artificial arc takes the round-off between the masses
        art_up[0], up[0], tree_flow[0] = 1, 1, net[0]
    else:
        art_up[0], up[0], tree_flow[0] = 0, 0, -net[0]
    pred[0] = n_real
    for y in range(n):
        attach(y, parent[y], parent, first_child, next_sib, prev_sib)
    for e in range(n_real):
        state[e] = 1
    for e in arcs:
        state[e] = 0
    return True


follow_callees(__name__, globals())
