"""Numba inter-route moves of the team OPTW ILS (see :mod:`searchtrack.plan.optw.ils_search`).

With several vehicles the ruin-and-recreate loop benefits from moves between routes that the
single-route reordering cannot make. Two are here, both classic in the team orienteering
literature (the *move* and route-level perturbations of Gunawan, Lau and Lu, "Well-tuned
algorithms for the team orienteering problem with time windows", 2017; the inter-route
neighbourhoods of Labadie et al., "The team orienteering problem with time windows: an LP-based
granular variable neighborhood search", 2012):

* :func:`relocate`: first-improvement moves of one visit to another route where it adds less
  travel than it saves, freeing time for later insertions;
* :func:`ruin_route`: remove every visit of one random route (a route-level perturbation), so the
  recreate step rebuilds that route from scratch around the others;
* :func:`replace`: put an unvisited customer of more profit in the place of a visit when it fits
  there (the *replace* move of Gunawan, Lau and Lu 2017, restricted to the visit's own place so
  that each candidate swap is an O(1) MaxShift test).

Same array layout as :mod:`searchtrack.plan.optw.ils_kernels`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.ils_kernels import (
    BIG,
    best_in_routes,
    insert_at,
    rand_int,
    schedule,
)


@njit(cache=True)
def _take_out(ins, sol, a, p):  # type: ignore[no-untyped-def]
    """Remove the visit at position ``p`` of route ``a``; returns False (and puts it back) if the
    shorter route misses a window (travel times that break the triangle inequality)."""
    rt, ln, own = sol[0], sol[1], sol[5]
    v = rt[a, p]
    n = ln[a]
    for q in range(p + 1, n):
        rt[a, q - 1] = rt[a, q]
    ln[a] = n - 1
    own[v] = -1
    schedule(ins, sol, a)
    if sol[4][a, 0] >= 0:
        return True
    insert_at(ins, sol, v, a, p)
    return False


@njit(cache=True)
def relocate(ins, sol, dirty):  # type: ignore[no-untyped-def]
    """Move visits between routes while some move shortens the total travel; returns the number
    of moves and flags the routes changed in ``dirty``.

    A visit ``v`` between ``u`` and ``w`` saves ``T[u,v] + T[v,w] − T[u,w]`` when taken out of
    its route; it goes to the feasible position of least Shift in another route if the travel it
    adds there is smaller (the first such route and visit, scanning routes and positions in
    order).
    """
    T = ins[0]
    rt, ln = sol[0], sol[1]
    m = ln.shape[0]
    moves = 0
    for a in range(m):
        p = 1
        while p < ln[a] - 1:
            u = rt[a, p - 1]
            v = rt[a, p]
            w = rt[a, p + 1]
            save = T[u, v] + T[v, w] - T[u, w]
            bb = -1
            bq = -1
            bc = save
            for b in range(m):
                if b == a:
                    continue
                _, q, _ = best_in_routes(ins, sol, v, b, b + 1)
                if q < 0:
                    continue
                i = rt[b, q - 1]
                j = rt[b, q]
                c = T[i, v] + T[v, j] - T[i, j]
                if c < bc:
                    bc = c
                    bb = b
                    bq = q
            if bb >= 0 and _take_out(ins, sol, a, p):
                insert_at(ins, sol, v, bb, bq)
                dirty[a] = True
                dirty[bb] = True
                moves += 1
            else:
                p += 1
    return moves


@njit(cache=True)
def ruin_route(ins, sol, rng):  # type: ignore[no-untyped-def]
    """Remove every visit of one random non-empty route (nothing if all are empty)."""
    rt, ln, own = sol[0], sol[1], sol[5]
    m = ln.shape[0]
    busy = 0
    for r in range(m):
        if ln[r] > 2:
            busy += 1
    if busy == 0:
        return
    pick = rand_int(rng, busy)
    for r in range(m):
        if ln[r] > 2:
            if pick == 0:
                for p in range(1, ln[r] - 1):
                    own[rt[r, p]] = -1
                rt[r, 1] = rt[r, ln[r] - 1]
                ln[r] = 2
                schedule(ins, sol, r)
                return
            pick -= 1


@njit(cache=True)
def replace(ins, sol, dirty):  # type: ignore[no-untyped-def]
    """Swap visits for unvisited customers of more profit, in the same place, while one fits;
    returns the number of swaps and flags the routes changed in ``dirty``.

    Replacing visit ``v`` between ``a`` and ``b`` by ``u`` is feasible when ``u``'s window is met
    and the Shift it causes at ``b`` is at most ``Wait_b + MaxShift_b``. Each round applies the
    feasible swap of most profit gained (ties: least Shift, then first route and position), so
    the profit grows strictly and the loop ends.
    """
    T, S, Op, C, P, cand = ins[0], ins[1], ins[2], ins[3], ins[4], ins[5]
    rt, ln, arr, st, ms, own = sol[0], sol[1], sol[2], sol[3], sol[4], sol[5]
    m = ln.shape[0]
    order = cand[np.argsort(-P[cand], kind="mergesort")]  # most profit first
    nc = order.shape[0]
    unv = np.empty(nc, dtype=np.int64)  # the unvisited, with their profit and window
    up = np.empty(nc, dtype=np.float64)
    uo = np.empty(nc, dtype=np.int64)
    uc = np.empty(nc, dtype=np.int64)
    moves = 0
    while True:
        nu = 0
        for g in order:
            if own[g] < 0:
                unv[nu] = g
                up[nu] = P[g]
                uo[nu] = Op[g]
                uc[nu] = C[g]
                nu += 1
        bg = 0.0
        bd = BIG
        br = -1
        bq = -1
        bu = -1
        for r in range(m):
            for q in range(1, ln[r] - 1):
                v = rt[r, q]
                a = rt[r, q - 1]
                b = rt[r, q + 1]
                dep = st[r, q - 1] + S[a]
                latest = st[r, q + 1] + ms[r, q + 1]  # latest feasible arrival at b
                for i in range(nu):
                    gain = up[i] - P[v]
                    if gain <= 1e-9 or gain < bg - 1e-9:
                        break  # profits only fall along ``unv``
                    if uc[i] < dep or uo[i] > latest:
                        continue  # u would start too late, or b be reached too late
                    u = unv[i]
                    x = dep + T[a, u]
                    if x > uc[i]:
                        continue
                    s = x if x > uo[i] else uo[i]
                    d = s + S[u] + T[u, b] - arr[r, q + 1]
                    if d > latest - arr[r, q + 1]:
                        continue
                    if gain > bg + 1e-9 or d < bd:
                        bg = gain
                        bd = d
                        br = r
                        bq = q
                        bu = u
        if br < 0:
            return moves
        own[rt[br, bq]] = -1
        rt[br, bq] = bu
        own[bu] = br
        schedule(ins, sol, br)
        dirty[br] = True
        moves += 1


follow_callees(__name__, globals())
