"""Numba kernels of the OPTW iterated local search (see :mod:`searchtrack.plan.optw.ils`).

Data layout (all integer times in ticks):

* ``ins = (T, S, O, C, P, cand)``: travel ``(N, N)``, service, open, close, profit over ``N = n + 1``
  vertices, the last being a *sink* that stands for the end vertex (or, for an open end, a free
  stop at the last visit); ``cand`` lists the customers worth visiting.
* ``sol = (rt, ln, arr, st, ms, own)``: per route the vertices ``rt[r, :ln[r]]`` (start first,
  sink last), arrival, service start and MaxShift per position (Vansteenwegen et al. 2009,
  eqs. 5.27–5.28 of the digest), and the route owning each vertex (−1 if unvisited).

Insertion feasibility is the O(1) test ``Shift ≤ Wait_j + MaxShift_j`` plus the inserted vertex's
own window; after a change the route's schedule is recomputed in O(length), which also handles
negative shifts (travel times break the triangle inequality).
"""

from __future__ import annotations

import numpy as np
from numba import njit

_BIG = np.int64(1) << np.int64(60)


# --------------------------------------------------------------------------- random numbers
@njit(cache=True)
def rand_u(rng: np.ndarray) -> float:
    """Uniform float in [0, 1) from a splitmix64 state ``rng`` (uint64[1])."""
    rng[0] += np.uint64(0x9E3779B97F4A7C15)
    z = rng[0]
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@njit(cache=True)
def rand_int(rng: np.ndarray, k: int) -> int:
    """Uniform integer in [0, k) (k ≥ 1)."""
    i = int(rand_u(rng) * k)
    return i if i < k else k - 1


# --------------------------------------------------------------------------- schedules
@njit(cache=True)
def schedule(ins, sol, r):  # type: ignore[no-untyped-def]
    """Recompute arrival, service start and MaxShift of route ``r``."""
    T, S, O, C = ins[0], ins[1], ins[2], ins[3]
    rt, ln, arr, st, ms = sol[0], sol[1], sol[2], sol[3], sol[4]
    n = ln[r]
    v = rt[r, 0]
    arr[r, 0] = O[v]
    st[r, 0] = O[v]
    for p in range(1, n):
        u = rt[r, p - 1]
        v = rt[r, p]
        a = st[r, p - 1] + S[u] + T[u, v]
        arr[r, p] = a
        st[r, p] = a if a > O[v] else O[v]
    ms[r, n - 1] = C[rt[r, n - 1]] - st[r, n - 1]
    for p in range(n - 2, -1, -1):
        x = st[r, p + 1] - arr[r, p + 1] + ms[r, p + 1]
        y = C[rt[r, p]] - st[r, p]
        ms[r, p] = x if x < y else y


@njit(cache=True)
def copy_sol(dst, src):  # type: ignore[no-untyped-def]
    """Copy solution ``src`` into ``dst`` (same shapes)."""
    for k in range(6):
        dst[k][...] = src[k]


@njit(cache=True)
def profit_of(ins, sol) -> float:  # type: ignore[no-untyped-def]
    """Total profit collected by ``sol``."""
    P = ins[4]
    rt, ln = sol[0], sol[1]
    total = 0.0
    for r in range(ln.shape[0]):
        for p in range(1, ln[r] - 1):
            total += P[rt[r, p]]
    return total


@njit(cache=True)
def time_of(sol) -> int:  # type: ignore[no-untyped-def]
    """Sum over routes of the arrival time at the sink (the tie-breaking secondary objective)."""
    ln, arr = sol[1], sol[2]
    total = 0
    for r in range(ln.shape[0]):
        total += arr[r, ln[r] - 1]
    return total


# --------------------------------------------------------------------------- insertion
@njit(cache=True)
def best_position(ins, sol, g):  # type: ignore[no-untyped-def]
    """Feasible insertion of ``g`` with the least Shift: ``(route, position, shift)``, route −1
    if none."""
    T, S, O, C = ins[0], ins[1], ins[2], ins[3]
    rt, ln, arr, st, ms = sol[0], sol[1], sol[2], sol[3], sol[4]
    og = O[g]
    cg = C[g]
    sg = S[g]
    br = -1
    bp = -1
    bd = _BIG
    for r in range(ln.shape[0]):
        for p in range(1, ln[r]):
            i = rt[r, p - 1]
            dep = st[r, p - 1] + S[i]
            if dep > cg:
                break  # departures only grow along a route
            a = dep + T[i, g]
            b = a if a > og else og
            if b > cg:
                continue
            j = rt[r, p]
            d = b + sg + T[g, j] - arr[r, p]
            if d < bd and d <= st[r, p] - arr[r, p] + ms[r, p]:
                bd = d
                br = r
                bp = p
    return br, bp, bd


@njit(cache=True)
def insert_at(ins, sol, g, r, p):  # type: ignore[no-untyped-def]
    """Insert vertex ``g`` at position ``p`` of route ``r`` and update its schedule."""
    rt, ln, own = sol[0], sol[1], sol[5]
    for q in range(ln[r], p, -1):
        rt[r, q] = rt[r, q - 1]
    rt[r, p] = g
    ln[r] += 1
    own[g] = r
    schedule(ins, sol, r)


@njit(cache=True)
def remove_range(ins, sol, r, p, k):  # type: ignore[no-untyped-def]
    """Remove the ``k`` visits at positions ``p .. p+k-1`` of route ``r`` (customers only)."""
    rt, ln, own = sol[0], sol[1], sol[5]
    n = ln[r]
    if p < 1:
        p = 1
    if p + k > n - 1:
        k = n - 1 - p
    if k <= 0:
        return
    for q in range(p, p + k):
        own[rt[r, q]] = -1
    for q in range(p + k, n):
        rt[r, q - k] = rt[r, q]
    ln[r] = n - k
    schedule(ins, sol, r)


@njit(cache=True)
def insert_greedy(ins, sol, rng, alpha, noise):  # type: ignore[no-untyped-def]
    """Insert unvisited customers by best ``P^alpha / Shift`` until none fits; returns the count.

    ``noise`` multiplies each score by ``1 + noise·U[0, 1)`` (randomised tie-breaking).
    """
    P, cand = ins[4], ins[5]
    own = sol[5]
    count = 0
    while True:
        bs = -1.0
        bg = -1
        br = -1
        bp = -1
        for g in cand:
            if own[g] >= 0:
                continue
            r, p, d = best_position(ins, sol, g)
            if r < 0:
                continue
            sc = P[g] ** alpha / (max(d, 0) + 1.0)
            if noise > 0.0:
                sc *= 1.0 + noise * rand_u(rng)
            if sc > bs:
                bs = sc
                bg = g
                br = r
                bp = p
        if bg < 0:
            return count
        insert_at(ins, sol, bg, br, bp)
        count += 1


# --------------------------------------------------------------------------- search loop
@njit(cache=True)
def better(pa, ta, pb, tb) -> bool:  # type: ignore[no-untyped-def]
    """Lexicographic comparison: more profit, then less time."""
    eps = 1e-9 * max(1.0, abs(pb))
    if pa > pb + eps:
        return True
    return pa >= pb - eps and ta < tb


@njit(cache=True)
def run_ils(ins, cur, best, rng, ctl, fctl, n_iter):  # type: ignore[no-untyped-def]
    """Run ``n_iter`` iterations of the ILS; ``ctl = [S, R, no_improve, iterations, r_max]``,
    ``fctl = [best_profit]``.

    The state (current, best, counters, random state) lives in the arrays, so the search can be
    resumed call after call with identical results whatever the batch sizes.
    """
    ln = cur[1]
    m = ln.shape[0]
    for _ in range(n_iter):
        insert_greedy(ins, cur, rng, 2.0, 0.0)
        pc = profit_of(ins, cur)
        tc = time_of(cur)
        if better(pc, tc, fctl[0], fctl[1]):
            copy_sol(best, cur)
            fctl[0] = pc
            fctl[1] = tc
            ctl[1] = 1
            ctl[2] = 0
        else:
            ctl[2] += 1
        # shake
        smallest = _BIG
        for r in range(m):
            if ln[r] - 2 < smallest:
                smallest = ln[r] - 2
        ctl[0] += ctl[1]
        ctl[1] += 1
        if smallest > 0 and ctl[0] >= smallest:
            ctl[0] = ctl[0] % smallest
        if ctl[1] >= ctl[4]:
            ctl[1] = 1
        for r in range(m):
            remove_range(ins, cur, r, 1 + ctl[0], ctl[1])
        ctl[3] += 1
