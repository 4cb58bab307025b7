"""Numba search loop of the OPTW ILS: ruin operators, route reordering, acceptance, restarts.

One iteration copies the current solution, ruins it (removes some visits, chosen by one of six
operators, the route ruin of :mod:`searchtrack.plan.optw.ils_moves` included), recreates it with
the randomised greedy insertion of :mod:`searchtrack.plan.optw.ils_kernels`, improves it by
reordering routes, moving visits between routes (optional), replacing visits by unvisited
customers of more profit (both in :mod:`searchtrack.plan.optw.ils_moves`) and inserting again, and
accepts it by simulated annealing on the profit (ties broken by time). The temperature falls
geometrically over cycles of growing length; each cycle restarts from the best solution (or from
one of an elite pool that the caller keeps). Only the routes that ruin and recreate changed are
reordered: the others are already locally optimal. Same array layout as the kernels module.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.ils_kernels import (
    best_position,
    better,
    copy_sol,
    insert_at,
    insert_greedy,
    profit_of,
    rand_int,
    rand_u,
    remove_marked,
    remove_range,
    schedule,
    stage_routes,
    time_of,
    visited_list,
)
from searchtrack.plan.optw.ils_moves import relocate, replace, ruin_route

# indices into the integer control array ``ctl``
C_ITER, C_SINCE_BEST, C_CYCLE_IT, C_CYCLE_LEN, C_RESTARTS, C_STAGED, C_SEEN = range(7)
# indices into the float state array ``fst``
F_BEST_P, F_BEST_T, F_CUR_P, F_CUR_T, F_TEMP, F_T0 = 0, 1, 2, 3, 4, 5
# indices into the parameter array ``par`` (see ``ils_tuning.Tuning``)
(P_KFRAC, P_T0, P_T1, P_CYCLE0, P_GROW, P_EQUAL, P_ALO, P_AHI, P_NOISE,
 P_WSEG, P_WRAND, P_WREL, P_WTARGET, P_WFIT, P_LS, P_WROUTE, P_KMAX, P_RELOC, P_SPLIT,
 P_ELITE, P_REPLACE, P_POOL) = range(22)


@njit(cache=True)
def ruin_segment(ins, sol, rng, k):  # type: ignore[no-untyped-def]
    """Remove ``k`` consecutive visits at a random position of each route."""
    ln = sol[1]
    for r in range(ln.shape[0]):
        nc = ln[r] - 2
        if nc > 0:
            remove_range(ins, sol, r, 1 + rand_int(rng, nc), k)


@njit(cache=True)
def ruin_random(ins, sol, rng, k, buf, mark):  # type: ignore[no-untyped-def]
    """Remove ``k`` visits chosen uniformly at random."""
    nv = visited_list(sol, buf)
    k = min(k, nv)
    for i in range(k):
        j = i + rand_int(rng, nv - i)
        buf[i], buf[j] = buf[j], buf[i]
        mark[buf[i]] = True
    remove_marked(ins, sol, mark)


@njit(cache=True)
def _vertex_starts(sol, vst):  # type: ignore[no-untyped-def]
    rt, ln, st = sol[0], sol[1], sol[3]
    for r in range(ln.shape[0]):
        for p in range(1, ln[r] - 1):
            vst[rt[r, p]] = st[r, p]


@njit(cache=True)
def _pick_unvisited(ins, sol, rng, nv):  # type: ignore[no-untyped-def]
    """A random unvisited candidate (−1 if none)."""
    cand = ins[5]
    own = sol[5]
    nu = cand.shape[0] - nv
    if nu <= 0:
        return -1
    pick = rand_int(rng, nu)
    for g in cand:
        if own[g] < 0:
            if pick == 0:
                return g
            pick -= 1
    return -1


@njit(cache=True)
def remove_vertex(ins, sol, w):  # type: ignore[no-untyped-def]
    """Remove visited customer ``w`` from its route."""
    rt, ln, own = sol[0], sol[1], sol[5]
    r = own[w]
    for p in range(1, ln[r] - 1):
        if rt[r, p] == w:
            remove_range(ins, sol, r, p, 1)
            return


@njit(cache=True)
def ruin_related(ins, sol, rng, k, buf, mark, key, vst, mode):  # type: ignore[no-untyped-def]
    """Remove up to ``k`` visits closest in travel and time to a seed vertex.

    ``mode`` 0: the seed is a random visit. 1: the seed is a random unvisited customer, inserted
    first once the ``k`` visits are gone if it fits. 2: as 1, but visits are removed one at a time
    only until the seed fits (a targeted "replace" move).
    """
    T, Op, C = ins[0], ins[2], ins[3]
    nv = visited_list(sol, buf)
    if nv == 0:
        return
    k = min(k, nv)
    _vertex_starts(sol, vst)
    if mode > 0:
        u = _pick_unvisited(ins, sol, rng, nv)
        if u < 0:
            return
        lo = Op[u]
        hi = C[u]
    else:
        u = buf[rand_int(rng, nv)]
        lo = vst[u]
        hi = vst[u]
    for i in range(nv):
        w = buf[i]
        dt = 0
        if vst[w] < lo:
            dt = lo - vst[w]
        elif vst[w] > hi:
            dt = vst[w] - hi
        key[i] = T[u, w] + T[w, u] + dt
    order = np.argsort(key[:nv])
    if mode == 2:
        for i in range(k):
            r, p, _ = best_position(ins, sol, u)
            if r >= 0:
                insert_at(ins, sol, u, r, p)
                return
            if sol[5][buf[order[i]]] >= 0:
                remove_vertex(ins, sol, buf[order[i]])
    else:
        for i in range(k):
            mark[buf[order[i]]] = True
        remove_marked(ins, sol, mark)
    if mode > 0:
        r, p, _ = best_position(ins, sol, u)
        if r >= 0:
            insert_at(ins, sol, u, r, p)


@njit(cache=True)
def _eval_tail(ins, seq, f, n, t_prev):  # type: ignore[no-untyped-def]
    """Forward schedule of ``seq[f:n]`` given the service start ``t_prev`` at ``seq[f-1]``;
    returns the arrival at ``seq[n-1]`` or −1 if a window is missed."""
    T, S, Op, C = ins[0], ins[1], ins[2], ins[3]
    t = t_prev
    a = t
    for p in range(f, n):
        u = seq[p - 1]
        v = seq[p]
        a = t + S[u] + T[u, v]
        if a > C[v]:
            return -1
        t = a if a > Op[v] else Op[v]
    return a


@njit(cache=True)
def reorder(ins, sol, r, seq):  # type: ignore[no-untyped-def]
    """First-improvement 2-opt and or-opt (segments of 1–3) on route ``r``, minimising travel,
    then arrival at the sink; returns True if the route changed."""
    T = ins[0]
    rt, ln, arr, st = sol[0], sol[1], sol[2], sol[3]
    n = ln[r]
    changed = False
    improved = True
    while improved:
        improved = False
        fin = arr[r, n - 1]
        # or-opt: move segment [i, i+q) before position j
        for q in range(1, 4):
            for i in range(1, n - q):
                a = rt[r, i - 1]
                s0 = rt[r, i]
                s1 = rt[r, i + q - 1]
                b = rt[r, i + q]
                gain_out = T[a, s0] + T[s1, b] - T[a, b]
                for j in range(1, n):
                    if i <= j <= i + q:
                        continue
                    c = rt[r, j - 1]
                    d = rt[r, j]
                    delta = T[c, s0] + T[s1, d] - T[c, d] - gain_out
                    if delta > 0:
                        continue
                    # build the new sequence from the first changed position
                    f = i if i < j else j
                    for p in range(f):
                        seq[p] = rt[r, p]
                    w = f
                    for p in range(f, n):
                        if p == j:
                            for x in range(q):
                                seq[w] = rt[r, i + x]
                                w += 1
                        if i <= p < i + q:
                            continue
                        seq[w] = rt[r, p]
                        w += 1
                    nf = _eval_tail(ins, seq, f, n, st[r, f - 1])
                    if nf < 0 or (delta == 0 and nf >= fin):
                        continue
                    for p in range(f, n):
                        rt[r, p] = seq[p]
                    schedule(ins, sol, r)
                    improved = True
                    changed = True
                    break
                if improved:
                    break
            if improved:
                break
        if improved:
            continue
        # 2-opt: reverse positions i..j
        for i in range(1, n - 2):
            a = rt[r, i - 1]
            inner_f = 0
            inner_b = 0
            for j in range(i + 1, n - 1):
                inner_f += T[rt[r, j - 1], rt[r, j]]
                inner_b += T[rt[r, j], rt[r, j - 1]]
                b = rt[r, j + 1]
                delta = (T[a, rt[r, j]] + T[rt[r, i], b] + inner_b
                         - T[a, rt[r, i]] - T[rt[r, j], b] - inner_f)
                if delta > 0:
                    continue
                for p in range(i):
                    seq[p] = rt[r, p]
                for p in range(i, j + 1):
                    seq[p] = rt[r, i + j - p]
                for p in range(j + 1, n):
                    seq[p] = rt[r, p]
                nf = _eval_tail(ins, seq, i, n, st[r, i - 1])
                if nf < 0 or (delta == 0 and nf >= fin):
                    continue
                for p in range(i, n):
                    rt[r, p] = seq[p]
                schedule(ins, sol, r)
                improved = True
                changed = True
                break
            if improved:
                break
    return changed


@njit(cache=True)
def local_search(ins, sol, rng, seq, inter=False, swap=False):  # type: ignore[no-untyped-def]
    """Alternate reordering of every route (and, with ``inter``, moves between routes; with
    ``swap``, replacements of visits by unvisited customers of more profit) and greedy insertion
    until none helps."""
    improve_routes(ins, sol, rng, seq, np.ones(sol[1].shape[0], dtype=np.bool_), inter, swap)


@njit(cache=True)
def improve_routes(ins, sol, rng, seq, dirty, inter, swap=False):  # type: ignore[no-untyped-def]
    """:func:`local_search` reordering only the routes flagged in ``dirty`` and those the other
    moves change (the others are already reordered); clears ``dirty``."""
    ln = sol[1]
    m = ln.shape[0]
    lens = np.empty(m, dtype=np.int64)
    pending = False
    while True:
        for r in range(m):
            if dirty[r]:
                dirty[r] = False
                if reorder(ins, sol, r, seq):
                    pending = True
        if inter and m > 1 and relocate(ins, sol, dirty) > 0:
            pending = True
            continue  # reorder the routes it changed, then look again
        if not pending:
            if swap and replace(ins, sol, dirty) > 0:
                pending = True
                continue  # reorder the routes it changed, then insert again
            return
        pending = False
        lens[:] = ln
        if insert_greedy(ins, sol, rng, 2.0, 0.0) == 0:
            if swap and replace(ins, sol, dirty) > 0:
                pending = True
                continue
            return
        for r in range(m):
            dirty[r] = ln[r] != lens[r]


@njit(cache=True)
def changed_routes(a, b, dirty):  # type: ignore[no-untyped-def]
    """Flag in ``dirty`` the routes whose visits differ between solutions ``a`` and ``b``."""
    for r in range(a[1].shape[0]):
        n = a[1][r]
        d = n != b[1][r]
        p = 1
        while not d and p < n - 1:
            d = a[0][r, p] != b[0][r, p]
            p += 1
        dirty[r] = d


@njit(cache=True)
def run_search(ins, cur, best, work, rng, ctl, fst, par, n_iter, buf, mark, key, vst, seq,  # type: ignore[no-untyped-def]
               rbuf, seen):
    """Run ``n_iter`` ruin-and-recreate iterations with local search from the current solution.

    All search state (solutions, counters, temperature, random state) lives in the arrays, so a
    search resumed call after call gives identical results whatever the batch sizes. With an
    elite pool (``par[P_ELITE] > 1``) it returns at the end of a cycle, before restarting: the
    caller sets ``cur``. With ``par[P_POOL] > 0`` it stages routes of local optima that close to
    the best profit in ``rbuf`` (``stage_routes``) and returns before ``rbuf`` can overflow.
    """
    wsum = (par[P_WSEG] + par[P_WRAND] + par[P_WREL] + par[P_WTARGET] + par[P_WFIT]
            + par[P_WROUTE])
    inter = par[P_RELOC] > 0.0
    swap = par[P_REPLACE] > 0.0
    dirty = np.zeros(cur[1].shape[0], dtype=np.bool_)
    for _ in range(n_iter):
        if par[P_POOL] > 0.0 and ctl[C_STAGED] + cur[1].shape[0] > rbuf.shape[0]:
            return  # the caller drains the staged routes
        copy_sol(work, cur)
        nv = visited_list(work, buf)
        kmax = max(int(par[P_KFRAC] * nv), min(nv, 4))  # short routes: up to all visits
        kmax = min(kmax, max(4, int(par[P_KMAX])))
        k = 1 + rand_int(rng, max(1, kmax))
        x = rand_u(rng) * wsum
        if x < par[P_WSEG]:
            m = work[1].shape[0]
            ruin_segment(ins, work, rng, (k + m - 1) // m if par[P_SPLIT] > 0.0 else k)
        elif x < par[P_WSEG] + par[P_WRAND]:
            ruin_random(ins, work, rng, k, buf, mark)
        elif x < par[P_WSEG] + par[P_WRAND] + par[P_WREL]:
            ruin_related(ins, work, rng, k, buf, mark, key, vst, 0)
        elif x < par[P_WSEG] + par[P_WRAND] + par[P_WREL] + par[P_WTARGET]:
            ruin_related(ins, work, rng, k, buf, mark, key, vst, 1)
        elif x < wsum - par[P_WROUTE]:
            ruin_related(ins, work, rng, k, buf, mark, key, vst, 2)
        else:
            ruin_route(ins, work, rng)
        alpha = par[P_ALO] + (par[P_AHI] - par[P_ALO]) * rand_u(rng)
        insert_greedy(ins, work, rng, alpha, par[P_NOISE])
        if par[P_LS] > 0.0:  # the routes ruin and recreate left alone are already reordered
            changed_routes(work, cur, dirty)
            improve_routes(ins, work, rng, seq, dirty, inter, swap)
        pw = profit_of(ins, work)
        tw = time_of(work)
        if par[P_POOL] > 0.0 and pw >= (1.0 - par[P_POOL]) * fst[F_BEST_P]:
            stage_routes(work, cur, rbuf, seen, ctl, C_STAGED, C_SEEN)
        accept = better(pw, tw, fst[F_CUR_P], fst[F_CUR_T])
        if not accept:
            d = pw - fst[F_CUR_P]
            if d >= -1e-9:
                accept = rand_u(rng) < par[P_EQUAL]
            elif fst[F_TEMP] > 0.0:
                accept = rand_u(rng) < np.exp(d / fst[F_TEMP])
        if accept:
            copy_sol(cur, work)
            fst[F_CUR_P] = pw
            fst[F_CUR_T] = tw
        if better(pw, tw, fst[F_BEST_P], fst[F_BEST_T]):
            copy_sol(best, work)
            fst[F_BEST_P] = pw
            fst[F_BEST_T] = tw
            ctl[C_SINCE_BEST] = 0
        else:
            ctl[C_SINCE_BEST] += 1
        ctl[C_ITER] += 1
        ctl[C_CYCLE_IT] += 1
        if ctl[C_CYCLE_IT] >= ctl[C_CYCLE_LEN]:
            ctl[C_CYCLE_IT] = 0
            ctl[C_RESTARTS] += 1
            ctl[C_CYCLE_LEN] = int(ctl[C_CYCLE_LEN] * par[P_GROW]) + 1
            if par[P_ELITE] > 1.0:  # the caller picks the restart (``ils._restart_elite``)
                fst[F_TEMP] = fst[F_T0]
                return
            copy_sol(cur, best)
            fst[F_CUR_P] = fst[F_BEST_P]
            fst[F_CUR_T] = fst[F_BEST_T]
        frac = ctl[C_CYCLE_IT] / ctl[C_CYCLE_LEN]
        fst[F_TEMP] = fst[F_T0] * (par[P_T1] ** frac)


follow_callees(__name__, globals())
