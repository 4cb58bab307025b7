"""Numba kernels of the OPTW iterated local search (see :mod:`searchtrack.plan.optw.ils`).

Data layout (all integer times in ticks):

* ``ins = (T, S, Op, C, P, cand)``: travel ``(N, N)``, service, open, close, profit over
  ``N = n + 1`` vertices, the last being a *sink* that stands for the end vertex (or, for an open
  end, a free stop at the last visit); ``cand`` lists the customers worth visiting.
* ``sol = (rt, ln, arr, st, ms, own)``: per route the vertices ``rt[r, :ln[r]]`` (start first,
  sink last), arrival, service start and MaxShift per position (Vansteenwegen et al. 2009;
  thesis 001 eqs. (5.27)–(5.28)), and the route owning each vertex (−1 if unvisited).

Insertion feasibility is the O(1) test ``Shift ≤ Wait_j + MaxShift_j`` plus the inserted vertex's
own window; after a change the route's schedule is recomputed in O(length), which also handles
negative shifts (travel times break the triangle inequality).
"""

from __future__ import annotations

import numpy as np
from numba import njit

BIG = np.int64(1) << np.int64(60)  #: larger than any time or shift


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
    T, S, Op, C = ins[0], ins[1], ins[2], ins[3]
    rt, ln, arr, st, ms = sol[0], sol[1], sol[2], sol[3], sol[4]
    n = ln[r]
    v = rt[r, 0]
    arr[r, 0] = Op[v]
    st[r, 0] = Op[v]
    for p in range(1, n):
        u = rt[r, p - 1]
        v = rt[r, p]
        a = st[r, p - 1] + S[u] + T[u, v]
        arr[r, p] = a
        st[r, p] = a if a > Op[v] else Op[v]
    ms[r, n - 1] = C[rt[r, n - 1]] - st[r, n - 1]
    for p in range(n - 2, -1, -1):
        x = st[r, p + 1] - arr[r, p + 1] + ms[r, p + 1]
        y = C[rt[r, p]] - st[r, p]
        ms[r, p] = x if x < y else y


@njit(cache=True)
def copy_sol(dst, src):  # type: ignore[no-untyped-def]
    """Copy solution ``src`` into ``dst`` (same shapes)."""
    dst[0][...] = src[0]
    dst[1][...] = src[1]
    dst[2][...] = src[2]
    dst[3][...] = src[3]
    dst[4][...] = src[4]
    dst[5][...] = src[5]


@njit(cache=True)
def profit_of(ins, sol):  # type: ignore[no-untyped-def]
    """Total profit collected by ``sol``."""
    P = ins[4]
    rt, ln = sol[0], sol[1]
    total = 0.0
    for r in range(ln.shape[0]):
        for p in range(1, ln[r] - 1):
            total += P[rt[r, p]]
    return total


@njit(cache=True)
def time_of(sol):  # type: ignore[no-untyped-def]
    """Sum over routes of the arrival time at the sink (the tie-breaking secondary objective)."""
    ln, arr = sol[1], sol[2]
    total = 0
    for r in range(ln.shape[0]):
        total += arr[r, ln[r] - 1]
    return total


# --------------------------------------------------------------------------- insertion
@njit(cache=True)
def best_in_routes(ins, sol, g, r0, r1):  # type: ignore[no-untyped-def]
    """Feasible insertion of ``g`` with the least Shift in routes ``r0 .. r1-1``: ``(route,
    position, shift)``, route −1 if none (ties: the first route, then the first position)."""
    T, S, Op, C = ins[0], ins[1], ins[2], ins[3]
    rt, ln, arr, st, ms = sol[0], sol[1], sol[2], sol[3], sol[4]
    og = Op[g]
    cg = C[g]
    sg = S[g]
    br = -1
    bp = -1
    bd = BIG
    need = og + sg
    for r in range(r0, r1):
        # latest service starts st + ms are non-decreasing along a route: skip the positions
        # whose successor must start before g could even finish (binary search)
        lo = 1
        hi = ln[r] - 1
        while lo < hi:
            mid = (lo + hi) // 2
            if st[r, mid] + ms[r, mid] < need:
                lo = mid + 1
            else:
                hi = mid
        for p in range(lo, ln[r]):
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
def best_position(ins, sol, g):  # type: ignore[no-untyped-def]
    """Feasible insertion of ``g`` with the least Shift: ``(route, position, shift)``, route −1
    if none."""
    return best_in_routes(ins, sol, g, 0, sol[1].shape[0])


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
def repair(ins, sol, r):  # type: ignore[no-untyped-def]
    """Make route ``r`` feasible again by dropping the visits where windows are first missed.

    Needed because removing a visit can delay the next one when travel times break the triangle
    inequality (by at most a tick for truncated distances).
    """
    C = ins[3]
    rt, ln, st, ms, own = sol[0], sol[1], sol[3], sol[4], sol[5]
    while ms[r, 0] < 0 and ln[r] > 2:
        n = ln[r]
        p = 1
        while p < n - 1 and st[r, p] <= C[rt[r, p]]:
            p += 1
        if p == n - 1:
            p = n - 2
        own[rt[r, p]] = -1
        for q in range(p + 1, n):
            rt[r, q - 1] = rt[r, q]
        ln[r] = n - 1
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
    repair(ins, sol, r)


@njit(cache=True)
def _swap(a, w, i, j):  # type: ignore[no-untyped-def]
    a[i], a[j] = a[j], a[i]
    w[i], w[j] = w[j], w[i]


@njit(cache=True)
def insert_greedy(ins, sol, rng, alpha, noise):  # type: ignore[no-untyped-def]
    """Insert unvisited customers by best ``P^alpha / Shift`` until none fits; returns the count.

    Every score is multiplied by ``1 + noise·U[0, 1)`` (randomised tie-breaking). A customer that
    fits nowhere is set aside until an insertion with a negative Shift (a shortcut, possible
    because travel times break the triangle inequality) makes room again: otherwise insertions
    only consume slack. Each customer's best position is cached per route and recomputed only
    for the routes changed since (an insertion changes one route), which gives the same choices
    as recomputing every position every time.
    """
    P, cand = ins[4], ins[5]
    own = sol[5]
    m = sol[1].shape[0]
    nvx = P.shape[0]
    alive = np.empty(cand.shape[0], dtype=np.int64)
    weight = np.empty(cand.shape[0], dtype=np.float64)
    cpos = np.empty((nvx, m), dtype=np.int64)
    cdel = np.empty((nvx, m), dtype=np.int64)
    cver = np.full((nvx, m), -1, dtype=np.int64)
    ver = np.zeros(m, dtype=np.int64)
    total = 0
    for g in cand:
        if own[g] < 0:
            alive[total] = g
            weight[total] = P[g] ** alpha
            total += 1
    na = total  # alive[:na] are tried, alive[na:total] are set aside
    count = 0
    while na > 0:
        bs = -1.0
        bi = -1
        br = -1
        bp = -1
        bd = BIG
        i = 0
        while i < na:
            g = alive[i]
            r = -1
            p = -1
            d = BIG
            for q in range(m):
                if cver[g, q] != ver[q]:
                    _, cpos[g, q], cdel[g, q] = best_in_routes(ins, sol, g, q, q + 1)
                    cver[g, q] = ver[q]
                if cpos[g, q] >= 0 and cdel[g, q] < d:
                    d = cdel[g, q]
                    r = q
                    p = cpos[g, q]
            if r < 0:
                na -= 1
                _swap(alive, weight, i, na)
                continue
            sc = weight[i] / ((d if d > 0 else 0) + 1.0)
            if noise > 0.0:
                sc *= 1.0 + noise * rand_u(rng)
            if sc > bs:
                bs = sc
                bi = i
                br = r
                bp = p
                bd = d
            i += 1
        if bi < 0:
            break
        insert_at(ins, sol, alive[bi], br, bp)
        ver[br] += 1
        count += 1
        na -= 1
        _swap(alive, weight, bi, na)
        total -= 1
        _swap(alive, weight, na, total)
        if bd < 0:
            na = total
    return count


# --------------------------------------------------------------------------- removal
@njit(cache=True)
def remove_marked(ins, sol, mark):  # type: ignore[no-untyped-def]
    """Remove every visited customer ``v`` with ``mark[v]`` set and clear the marks."""
    rt, ln, own = sol[0], sol[1], sol[5]
    for r in range(ln.shape[0]):
        n = ln[r]
        q = 1
        for p in range(1, n - 1):
            v = rt[r, p]
            if mark[v]:
                own[v] = -1
                mark[v] = False
            else:
                rt[r, q] = v
                q += 1
        rt[r, q] = rt[r, n - 1]
        if q + 1 != n:
            ln[r] = q + 1
            schedule(ins, sol, r)
            repair(ins, sol, r)


@njit(cache=True)
def visited_list(sol, out):  # type: ignore[no-untyped-def]
    """Write the visited customers into ``out``; return their number."""
    rt, ln = sol[0], sol[1]
    k = 0
    for r in range(ln.shape[0]):
        for p in range(1, ln[r] - 1):
            out[k] = rt[r, p]
            k += 1
    return k


@njit(cache=True)
def better(pa, ta, pb, tb):  # type: ignore[no-untyped-def]
    """Lexicographic comparison: more profit, then less time."""
    eps = 1e-9 * max(1.0, abs(pb))
    if pa > pb + eps:
        return True
    return pa >= pb - eps and ta < tb


# --------------------------------------------------------------------------- route pool
@njit(cache=True)
def route_key(rt, r, n):  # type: ignore[no-untyped-def]
    """Order-free 62-bit key of the customer set of route ``r`` (its first ``n`` positions): a
    sum of splitmix64 hashes, so the same customers in another order share a key."""
    h = np.uint64(0)
    for p in range(1, n - 1):
        z = np.uint64(rt[r, p] + 1) * np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        h += z ^ (z >> np.uint64(31))
    return np.int64(h >> np.uint64(2))


@njit(cache=True)
def stage_routes(sol, old, rbuf, seen, ctl, c_staged, c_seen):  # type: ignore[no-untyped-def]
    """Copy the routes of ``sol`` that differ from those of ``old`` into the rows of ``rbuf``
    from ``ctl[c_staged]`` on, as ``(key, visits, arrival at the sink, customers…)``, unless the
    open-addressing table ``seen`` (rows ``(key + 1, arrival)``, ``ctl[c_seen]`` in use; cleared
    when half full) holds the same customers with no later arrival."""
    rt, ln, arr = sol[0], sol[1], sol[2]
    mask = seen.shape[0] - 1
    for r in range(ln.shape[0]):
        n = ln[r]
        if n <= 2:
            continue
        same = n == old[1][r]
        p = 1
        while same and p < n - 1:
            same = rt[r, p] == old[0][r, p]
            p += 1
        if same:
            continue
        key = route_key(rt, r, n)
        a = arr[r, n - 1]
        h = key & mask
        while seen[h, 0] != 0 and seen[h, 0] != key + 1:
            h = (h + 1) & mask
        if seen[h, 0] != 0 and seen[h, 1] <= a:
            continue
        if seen[h, 0] == 0:
            if 2 * ctl[c_seen] >= seen.shape[0]:
                seen[:, 0] = 0
                ctl[c_seen] = 0
                h = key & mask
            seen[h, 0] = key + 1
            ctl[c_seen] += 1
        seen[h, 1] = a
        k = ctl[c_staged]
        rbuf[k, 0] = key
        rbuf[k, 1] = n - 2
        rbuf[k, 2] = a
        rbuf[k, 3 : n + 1] = rt[r, 1 : n - 1]
        ctl[c_staged] = k + 1
