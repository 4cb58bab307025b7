"""Numba building blocks of the OPTW labelling kernel
(:mod:`searchtrack.plan.optw.labelling_kernels`): growable label arrays, all-pairs shortest
durations, the out-of-reach counts (Feillet et al. 2004), the completion and outside-profit
bounds, the elementarity check, the subset-row cut penalty of label dominance, and the hash
table that groups the labels of a vertex by their ng-memory (Baldacci, Mingozzi & Roberti 2011).
"""

from __future__ import annotations

import numpy as np
from numba import njit, objmode

from searchtrack.core.interrupt import stop_clock


@njit(cache=True)
def clock() -> float:
    """The wall clock, or +inf once a stop is requested (the kernel then stops as at its
    deadline)."""
    with objmode(now="float64"):
        now = stop_clock()
    return now


@njit(cache=True)
def grow1(a, cap):  # type: ignore[no-untyped-def]
    """A copy of the 1-d array ``a`` with room for ``cap`` entries (the new ones unset)."""
    b = np.empty(cap, dtype=a.dtype)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def grow2(a, cap):  # type: ignore[no-untyped-def]
    """A copy of the 2-d array ``a`` with room for ``cap`` rows (the new ones zero)."""
    b = np.zeros((cap, a.shape[1]), dtype=a.dtype)
    b[: a.shape[0]] = a
    return b


@njit(cache=True)
def shortest_paths(dur, big):  # type: ignore[no-untyped-def]
    """All-pairs shortest durations (Floyd–Warshall), capped at ``big`` (no path)."""
    n = dur.shape[0]
    sp = dur.copy()
    for k in range(n):
        for i in range(n):
            dik = sp[i, k]
            if dik >= big:
                continue
            for j in range(n):
                d = dik + sp[k, j]
                if d < sp[i, j]:
                    sp[i, j] = d
    return sp


@njit(cache=True, inline="always")
def unreach_count(thr, v, t):  # type: ignore[no-untyped-def]
    """Number of entries of the sorted row ``thr[v]`` below ``t`` (vertices out of reach)."""
    lo = 0
    hi = thr.shape[1]
    while lo < hi:
        mid = (lo + hi) >> 1
        if thr[v, mid] < t:
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always")
def completion(tab, v, t, horizon, width, prof):  # type: ignore[no-untyped-def]
    """Upper bound on the profit still collectable after serving ``v`` at time ``t``.

    ``tab[v, k]`` is the best profit (``v`` included) of an opposite-direction label at ``v``
    whose time lies in bucket ``k`` or earlier; the opposite time of ``t`` is ``horizon − t``.
    """
    s = horizon - t
    if s < 0:
        return -np.inf
    k = s // width
    if k >= tab.shape[1]:
        k = tab.shape[1] - 1
    return tab[v, k] - prof[v]


@njit(cache=True)
def outside_tables(cum, ng, prof):  # type: ignore[no-untyped-def]
    """What the bound without a table needs, so that it costs O(|ng-set|), not O(N).

    ``outside[v, r]`` is the total ``prof`` of the customers not among the first ``r`` that fall
    out of reach from ``v`` (``cum[v, r]``); ``ngl[ngp[v]:ngp[v + 1]]`` lists ``v`` and the
    customers of its ng-set.
    """
    n, k1, nw = cum.shape
    one = np.uint64(1)
    total = 0.0
    for c in range(1, n - 1):
        total += prof[c]
    outside = np.empty((n, k1))
    for v in range(n):
        outside[v, 0] = total
        for r in range(1, k1):
            s = outside[v, r - 1]
            for w in range(nw):
                diff = cum[v, r, w] & ~cum[v, r - 1, w]
                b = 0
                while diff:
                    if diff & one:
                        s -= prof[w * 64 + b]
                    diff >>= one
                    b += 1
            outside[v, r] = s
    ngp = np.zeros(n + 1, dtype=np.int64)
    ngl = np.empty(n * n, dtype=np.int64)
    m = 0
    for v in range(n):
        for c in range(1, n - 1):
            if c == v or (ng[v, c >> 6] >> np.uint64(c & 63)) & one:
                ngl[m] = c
                m += 1
        ngp[v + 1] = m
    return outside, ngp, ngl


@njit(cache=True, inline="always")
def profit_outside(outside, ngp, ngl, cum, j, r, memo, prof):  # type: ignore[no-untyped-def]
    """Total profit of the customers neither in ``memo`` (the ng-memory at ``j``) nor among the
    ``r`` out of reach from ``j`` (the customers ``1 … N − 2`` not in the label's mask)."""
    one = np.uint64(1)
    total = outside[j, r]
    for e in range(ngp[j], ngp[j + 1]):
        c = ngl[e]
        w = c >> 6
        bit = np.uint64(c & 63)
        if (memo[w] >> bit) & one and not (cum[j, r, w] >> bit) & one:
            total -= prof[c]
    return total


@njit(cache=True, inline="always")
def is_elementary(par, lv, leaf, stamp, mark):  # type: ignore[no-untyped-def]
    """True when the path ending at label ``leaf`` visits no vertex twice."""
    x = leaf
    while x >= 0:
        v = lv[x]
        if stamp[v] == mark:
            return False
        stamp[v] = mark
        x = par[x]
    return True


@njit(cache=True, inline="always")
def sig_of(bits, c, sig):  # type: ignore[no-untyped-def]
    """``Σ sig[c + k]`` over the set bits ``k`` of the 64-bit word ``bits``."""
    one = np.uint64(1)
    total = 0.0
    while bits:
        if bits & one:
            total += sig[c]
        bits >>= one
        c += 1
    return total


@njit(cache=True, inline="always")
def cut_penalty(lc, x, state, sig, owed_by_x):  # type: ignore[no-untyped-def]
    """``Σ sig[c]`` over the cuts ``c`` set in label ``x``'s states ``lc[x]`` and not in
    ``state`` (``owed_by_x``), or set in ``state`` and not in ``lc[x]``.

    A label in state 1 for a cut that another label has in state 0 may still pay that cut's
    dual, so to dominate the other its profit must exceed the other's by the sum of such duals
    (Jepsen et al. 2008; Pecin et al. 2017).
    """
    total = 0.0
    for w in range(state.shape[0]):
        bits = lc[x, w] & ~state[w] if owed_by_x else state[w] & ~lc[x, w]
        total += sig_of(bits, w * 64, sig)
    return total


@njit(cache=True, inline="always")
def cut_shared(fc, f, bc, b, sig):  # type: ignore[no-untyped-def]
    """``Σ sig[c]`` over the cuts ``c`` whose state bit is set in both ``fc[f]`` and ``bc[b]``."""
    total = 0.0
    for w in range(fc.shape[1]):
        total += sig_of(fc[f, w] & bc[b, w], w * 64, sig)
    return total


@njit(cache=True, inline="always")
def _hash(v, key):  # type: ignore[no-untyped-def]
    h = np.uint64(v) * np.uint64(0x9E3779B97F4A7C15)
    for w in range(key.shape[0]):
        h = (h ^ key[w]) * np.uint64(0xBF58476D1CE4E5B9)
        h ^= h >> np.uint64(31)
    return h


@njit(cache=True, inline="always")
def find_group(slots, gv, gkey, v, key):  # type: ignore[no-untyped-def]
    """Group of ``(v, key)``, or ``-1 − slot`` with the free slot where it would go."""
    m = np.uint64(slots.shape[0] - 1)
    h = np.int64(_hash(v, key) & m)
    while slots[h] >= 0:
        g = slots[h]
        if gv[g] == v:
            same = True
            for w in range(key.shape[0]):
                if gkey[g, w] != key[w]:
                    same = False
                    break
            if same:
                return g
        h = np.int64((np.uint64(h) + np.uint64(1)) & m)
    return -1 - h


@njit(cache=True)
def rehash(slots, gv, gkey, n_groups):  # type: ignore[no-untyped-def]
    """The hash table of :func:`find_group` at twice the size, holding the same groups."""
    new = np.full(2 * slots.shape[0], -1, dtype=np.int64)
    m = np.uint64(new.shape[0] - 1)
    for g in range(n_groups):
        h = np.int64(_hash(gv[g], gkey[g]) & m)
        while new[h] >= 0:
            h = np.int64((np.uint64(h) + np.uint64(1)) & m)
        new[h] = g
    return new
