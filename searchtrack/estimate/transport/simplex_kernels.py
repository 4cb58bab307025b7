"""Numba kernels of the network simplex (see :mod:`searchtrack.estimate.transport.simplex`).

Tree arrays cover the nodes plus the artificial root (last index): ``parent``, ``pred`` (the
arc to the parent), ``up`` (1 if ``pred`` points to the parent), ``depth``, potentials ``pi``
(reduced cost ``c_e + pi[tail] − pi[head]``, zero on tree arcs), ``tree_flow`` (flow on
``pred``) and child lists ``first_child`` / ``next_sib`` / ``prev_sib``. Arc ``n_real + u`` is
node ``u``'s artificial arc (``u → root`` at cost 0 if ``art_up[u]``, else ``root → u`` at the
big-M cost). ``state[e]`` is 1 for real non-tree arcs, 0 for tree arcs.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core.types import FloatArray, IntArray

EPS = 1e-14  # pricing tolerance, relative to max(|cost|, |potentials|) of the arc

# return codes of pivots()
OPTIMAL, MORE, UNBOUNDED = 0, 1, 2


@njit(cache=True)
def work_arrays(n: int, n_real: int) -> tuple[
        NDArray[np.int8], IntArray, IntArray, NDArray[np.int8], IntArray, FloatArray, FloatArray,
        IntArray, IntArray, IntArray, NDArray[np.int8], IntArray, IntArray, IntArray]:
    """The work arrays of a network simplex on ``n`` nodes and ``n_real`` real arcs:
    ``(art_up, parent, pred, up, depth, pi, tree_flow, first_child, next_sib, prev_sib, state,
    cursor, stack, stem)``, the tree's over ``n + 1`` nodes (the artificial root last)."""
    return (np.zeros(n, dtype=np.int8), np.empty(n + 1, dtype=np.int64),
            np.empty(n + 1, dtype=np.int64), np.zeros(n + 1, dtype=np.int8),
            np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.float64),
            np.zeros(n + 1, dtype=np.float64), np.empty(n + 1, dtype=np.int64),
            np.full(n + 1, -1, dtype=np.int64), np.full(n + 1, -1, dtype=np.int64),
            np.ones(n_real, dtype=np.int8), np.zeros(1, dtype=np.int64),
            np.empty(n + 1, dtype=np.int64), np.empty(n + 1, dtype=np.int64))


@njit(cache=True, inline="always")
def _ends(
    e: int, tail: IntArray, head: IntArray, ncols: int, nrows: int, n_real: int, root: int,
    art_up: NDArray[np.int8],
) -> tuple[int, int]:
    if e >= n_real:
        u = e - n_real
        if art_up[u]:
            return u, root
        return root, u
    if ncols > 0:
        return e // ncols, nrows + e % ncols
    return tail[e], head[e]


@njit(cache=True)
def init_tree(
    supply: FloatArray, art_cost: float, art_up: NDArray[np.int8], parent: IntArray,
    pred: IntArray, up: NDArray[np.int8], depth: IntArray, pi: FloatArray, tree_flow: FloatArray,
    first_child: IntArray, next_sib: IntArray, prev_sib: IntArray, n_real: int,
) -> None:
    n = supply.shape[0]
    root = n
    parent[root] = -1
    pred[root] = -1
    depth[root] = 0
    pi[root] = 0.0
    first_child[root] = -1
    for u in range(n):
        parent[u] = root
        pred[u] = n_real + u
        depth[u] = 1
        first_child[u] = -1
        # artificial arc u -> root (cost 0) for supply, root -> u (cost art_cost) for demand
        if supply[u] >= 0.0:
            art_up[u] = 1
            up[u] = 1
            pi[u] = 0.0
            tree_flow[u] = supply[u]
        else:
            art_up[u] = 0
            up[u] = 0
            pi[u] = art_cost
            tree_flow[u] = -supply[u]
        prev_sib[u] = u - 1
        next_sib[u] = u + 1 if u + 1 < n else -1
    if n > 0:
        first_child[root] = 0


@njit(cache=True)
def refresh(
    cost: FloatArray, n_real: int, art_cost: float, art_up: NDArray[np.int8], parent: IntArray,
    pred: IntArray, up: NDArray[np.int8], depth: IntArray, pi: FloatArray, first_child: IntArray,
    next_sib: IntArray, stack: IntArray,
) -> None:
    """Recompute every potential and depth from the tree (removes accumulated round-off)."""
    root = parent.shape[0] - 1
    pi[root] = 0.0
    depth[root] = 0
    top = 0
    stack[top] = root
    top += 1
    while top > 0:
        top -= 1
        x = stack[top]
        y = first_child[x]
        while y >= 0:
            e = pred[y]
            c = (0.0 if art_up[e - n_real] else art_cost) if e >= n_real else cost[e]
            pi[y] = pi[x] - c if up[y] else pi[x] + c
            depth[y] = depth[x] + 1
            stack[top] = y
            top += 1
            y = next_sib[y]


@njit(cache=True, inline="always")
def _violates(rc: float, c: float, pi_s: float, pi_t: float) -> bool:
    return rc < -EPS * max(abs(c), abs(pi_s), abs(pi_t))


@njit(cache=True)
def _entering_dense(
    cost: FloatArray, ncols: int, nrows: int, state: NDArray[np.int8], pi: FloatArray,
    cursor: IntArray, block: int,
) -> int:
    """Block search over an implicit ``nrows × ncols`` bipartite graph, a row segment at a time."""
    n_real = cost.shape[0]
    best = 0.0
    best_e = -1
    e = cursor[0]
    scanned = 0
    while scanned < n_real:
        left = min(block, n_real - scanned)
        while left > 0:
            i = e // ncols
            j0 = e - i * ncols
            j1 = min(ncols, j0 + left)
            pi_i = pi[i]
            base = i * ncols
            for j in range(j0, j1):
                if state[base + j]:
                    rc = cost[base + j] + pi_i - pi[nrows + j]
                    if rc < best:
                        best = rc
                        best_e = base + j
            left -= j1 - j0
            scanned += j1 - j0
            e = base + j1
            if e == n_real:
                e = 0
        if best_e >= 0:
            s = best_e // ncols
            t = nrows + best_e - s * ncols
            if _violates(best, cost[best_e], pi[s], pi[t]):
                cursor[0] = e
                return best_e
    return -1


@njit(cache=True)
def _entering_arcs(
    tail: IntArray, head: IntArray, cost: FloatArray, state: NDArray[np.int8], pi: FloatArray,
    cursor: IntArray, block: int,
) -> int:
    """Block search over explicit arcs: the most negative reduced cost of the first good block."""
    n_real = cost.shape[0]
    best = 0.0
    best_e = -1
    e = cursor[0]
    count = block
    for _ in range(n_real):
        if state[e]:
            rc = cost[e] + pi[tail[e]] - pi[head[e]]
            if rc < best:
                best = rc
                best_e = e
        e += 1
        if e == n_real:
            e = 0
        count -= 1
        if count == 0 or e == cursor[0]:
            if best_e >= 0 and _violates(best, cost[best_e], pi[tail[best_e]],
                                         pi[head[best_e]]):
                cursor[0] = e
                return best_e
            count = block
    return -1


@njit(cache=True, inline="always")
def _detach(x: int, parent: IntArray, first_child: IntArray, next_sib: IntArray,
            prev_sib: IntArray) -> None:
    a = prev_sib[x]
    b = next_sib[x]
    if a >= 0:
        next_sib[a] = b
    else:
        first_child[parent[x]] = b
    if b >= 0:
        prev_sib[b] = a


@njit(cache=True, inline="always")
def attach(x: int, p: int, parent: IntArray, first_child: IntArray, next_sib: IntArray,
           prev_sib: IntArray) -> None:
    """Make node ``x`` the first child of ``p`` in the spanning tree's child lists."""
    b = first_child[p]
    next_sib[x] = b
    prev_sib[x] = -1
    if b >= 0:
        prev_sib[b] = x
    first_child[p] = x
    parent[x] = p


@njit(cache=True)
def pivots(
    max_pivots: int, tail: IntArray, head: IntArray, cost: FloatArray, ncols: int, nrows: int,
    n_real: int, art_up: NDArray[np.int8], state: NDArray[np.int8], parent: IntArray,
    pred: IntArray, up: NDArray[np.int8], depth: IntArray, pi: FloatArray,
    tree_flow: FloatArray, first_child: IntArray, next_sib: IntArray, prev_sib: IntArray,
    cursor: IntArray, stack: IntArray, stem: IntArray,
) -> tuple[int, int]:
    """Run up to ``max_pivots`` pivots; return (pivots done, OPTIMAL | MORE | UNBOUNDED)."""
    root = parent.shape[0] - 1
    block = max(int(math.sqrt(n_real)), 10)
    done = 0
    while done < max_pivots:
        if ncols > 0:
            e_in = _entering_dense(cost, ncols, nrows, state, pi, cursor, block)
        else:
            e_in = _entering_arcs(tail, head, cost, state, pi, cursor, block)
        if e_in < 0:
            return done, OPTIMAL
        s, t = _ends(e_in, tail, head, ncols, nrows, n_real, root, art_up)
        # join: the lowest common ancestor of s and t
        u, v = s, t
        while u != v:
            if depth[u] > depth[v]:
                u = parent[u]
            elif depth[v] > depth[u]:
                v = parent[v]
            else:
                u = parent[u]
                v = parent[v]
        join = u
        # leaving arc: the last blocking arc met going round the cycle s -> t -> join -> s
        delta = np.inf
        u_out = -1
        side = 0
        u = s
        while u != join:  # traversed downwards: an arc pointing up is backward
            if up[u] and tree_flow[u] < delta:
                delta = tree_flow[u]
                u_out = u
                side = 1
            u = parent[u]
        u = t
        while u != join:  # traversed upwards: an arc pointing down is backward
            if not up[u] and tree_flow[u] <= delta:
                delta = tree_flow[u]
                u_out = u
                side = 2
            u = parent[u]
        if u_out < 0:
            return done, UNBOUNDED
        if delta > 0.0:
            u = s
            while u != join:
                tree_flow[u] += -delta if up[u] else delta
                u = parent[u]
            u = t
            while u != join:
                tree_flow[u] += delta if up[u] else -delta
                u = parent[u]
        u_in, v_in = (s, t) if side == 1 else (t, s)
        e_out = pred[u_out]
        if e_out < n_real:
            state[e_out] = 1
        state[e_in] = 0
        # re-root the cut subtree at u_in: reverse the stem u_in -> ... -> u_out
        k = 0
        w = u_in
        while True:
            stem[k] = w
            k += 1
            if w == u_out:
                break
            w = parent[w]
        for i in range(k):
            _detach(stem[i], parent, first_child, next_sib, prev_sib)
        for i in range(k - 1, 0, -1):
            w = stem[i]
            c = stem[i - 1]
            pred[w] = pred[c]
            up[w] = 1 - up[c]
            tree_flow[w] = tree_flow[c]
            attach(w, c, parent, first_child, next_sib, prev_sib)
        pred[u_in] = e_in
        up[u_in] = 1 if u_in == s else 0
        tree_flow[u_in] = delta
        attach(u_in, v_in, parent, first_child, next_sib, prev_sib)
        # shift potentials of the moved subtree so that e_in has zero reduced cost; fix depths
        sigma = (pi[v_in] - cost[e_in] if u_in == s else pi[v_in] + cost[e_in]) - pi[u_in]
        pi[u_in] += sigma
        depth[u_in] = depth[v_in] + 1
        top = 0
        stack[top] = u_in
        top += 1
        while top > 0:
            top -= 1
            x = stack[top]
            y = first_child[x]
            while y >= 0:
                pi[y] += sigma
                depth[y] = depth[x] + 1
                stack[top] = y
                top += 1
                y = next_sib[y]
        done += 1
    return done, MORE
