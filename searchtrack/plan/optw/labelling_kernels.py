"""Numba kernel of the OPTW labelling solver: one bounded pass of ng/DSSR-relaxed labelling.

A pass works on a *core graph* (source ``src``, customers, sink ``snk``; see
:mod:`searchtrack.plan.optw.labelling_core`, whose ``run_pass`` calls the kernel) in its own time
axis: the forward pass in service-start ticks, the backward pass on the reversed graph with time
``H − τ``. Both are the same forward labelling algorithm (Righini & Salani 2009, §3), so there
is only one kernel.

A label is ``(vertex, time, profit, mask)``: ``mask`` holds the vertices the label may not
visit, the ng-memory (Baldacci, Mingozzi & Roberti 2011) joined with the vertices that can no
longer be reached in time (Feillet et al. 2004). Label ``a`` dominates ``b`` at the same vertex
when ``time_a ≤ time_b``, ``profit_a ≥ profit_b`` and ``mask_a ⊆ mask_b`` (with subset-row cuts,
a label also carries their states and ``profit_a`` must cover the cuts ``a`` may still pay for
and ``b`` not). Labels are expanded in
order of time from a bucket queue. A new label is compared with every live label at its vertex
that has the same ng-memory (found through a hash table) and with the most recent others.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.labelling_primitives import (
    clock,
    completion,
    dominance,
    find_group,
    grow1,
    grow2,
    is_elementary,
    outside_tables,
    profit_outside,
    rehash,
    sig_of,
    unreach_count,
)

DONE = 0  # the pass finished: every label was expanded or pruned
TIMEOUT = 1  # the deadline passed
FULL = 2  # the label store reached its capacity
ENOUGH = 3  # collect mode: the asked number of elementary paths was found

_CHECK_EVERY = 64  # expanded labels between two clock reads


@njit(cache=True)
def label_pass(  # type: ignore[no-untyped-def]
    dur, succ_ptr, succ, opn, cls, prof, ng, thr, cum, src, snk,
    tab, use_tab, horizon, width, qshift, lb, ub, gap, cap_max, deadline, scan, collect, bprof,
    cut_s, cut_m, sig, tstop,
):
    """Run one labelling pass; see the module docstring.

    Parameters
    ----------
    dur
        ``(N, N)`` service-plus-travel ticks of each arc.
    succ_ptr, succ
        Successor lists (CSR) of the feasible arcs.
    opn, cls
        ``(N,)`` window on the service start of each vertex in this pass's time axis.
    prof
        ``(N,)`` profit of each vertex (0 for ``src`` and ``snk``); may be negative when
        ``bprof`` bounds it from above.
    ng
        ``(N, W)`` ng-neighbourhood bitmask of each vertex (own bit included).
    thr, cum
        ``thr[v]`` sorted times after which the customers fall out of reach from ``v``;
        ``cum[v, r]`` the mask of the first ``r`` of them.
    tab, use_tab, horizon, width
        Opposite-direction profit table used as completion bound (see
        :func:`searchtrack.plan.optw.labelling_primitives.completion`);
        bucket ``k`` covers times ``[k·width, (k+1)·width)``.
    qshift
        Labels are expanded in order of ``time >> qshift`` (0: exact time order).
    lb, ub, gap
        Best known profit and an upper bound on the optimum; a label survives only if its bound
        reaches ``lb + gap``, and the pass stops once ``lb + gap > ub``.
    cap_max
        Most labels to store.
    deadline
        ``time.perf_counter()`` value at which to stop.
    scan
        A new label is compared with every label at its vertex with the same ng-memory, and
        with the ``scan`` most recent other labels there.
    collect
        0: search for the best path (each elementary path found raises ``lb``). ``K > 0``
        (pricing mode): keep ``lb`` fixed and collect the elementary paths reaching ``lb + gap``
        in ``found``, stopping with ``ENOUGH`` once ``K`` are found.
    bprof
        ``(N,)`` non-negative upper bounds on ``prof`` for the bound without a table (``prof``
        itself when profits are non-negative).
    cut_s, cut_m, sig
        Limited-memory subset-row cuts (Pecin et al. 2017): ``(N, C)`` bitmasks of the cuts whose
        subset, and whose memory, hold each vertex, and ``sig[c] ≥ 0`` the dual of cut ``c``. A
        label keeps a bit per cut, cleared on entering a vertex outside the cut's memory and
        toggled on entering one of its subset; entering a subset vertex with the bit set costs
        ``sig[c]``. ``C = 0``: no cuts. ``bprof`` and ``tab`` must bound profits without the
        cuts' costs (the costs of a path's prefix are among the whole path's).
    tstop
        Labels (sink labels included) whose time would exceed ``tstop`` are not made: the
        half-way limit of bidirectional labelling (the horizon or more: no limit).

    Returns
    -------
    tuple
        ``(status, lb, best, sinks, n_sinks, lv, lp, par, n_labels, own, pops, work, found,
        n_found, lt, lmem, lc, alive)``: ``best`` the sink label of the best elementary path
        that beat the given ``lb`` (−1 if none), ``sinks[:n_sinks]`` sink labels of
        non-elementary paths that reached ``lb + gap`` when found, ``own`` this pass's profit
        table (same bucketing as ``tab``), ``pops`` the labels expanded, ``work`` the labels
        visited by dominance checks, ``found[:n_found]`` the sink labels of the elementary
        paths collected (collect mode);
        ``lt``, ``lmem``, ``lc`` and ``alive`` each label's time, ng-memory (own vertex
        included), cut states and whether it is undominated.
    """
    n = dur.shape[0]
    nw = ng.shape[1]
    cap = min(1 << 15, cap_max)
    lv = np.empty(cap, dtype=np.int64)  # vertex
    lt = np.empty(cap, dtype=np.int64)  # time
    lp = np.empty(cap, dtype=np.float64)  # profit
    lbnd = np.empty(cap, dtype=np.float64)  # profit + completion bound
    par = np.empty(cap, dtype=np.int64)  # parent label
    nxt = np.empty(cap, dtype=np.int64)  # next label at the same vertex
    qnx = np.empty(cap, dtype=np.int64)  # next label in the same time bucket
    alive = np.empty(cap, dtype=np.bool_)  # not dominated
    lm = np.zeros((cap, nw), dtype=np.uint64)
    nc = cut_s.shape[1]
    lc = np.zeros((cap, nc), dtype=np.uint64)  # subset-row cut states
    state = np.zeros(nc, dtype=np.uint64)
    head = np.full(n, -1, dtype=np.int64)  # labels of each vertex
    qhead = np.full((horizon >> qshift) + 1, -1, dtype=np.int64)
    own = np.full(tab.shape, -np.inf)
    sinks = np.empty(64, dtype=np.int64)
    n_sinks = 0
    found = np.empty(64, dtype=np.int64)
    n_found = 0
    stamp = np.zeros(n, dtype=np.int64)
    mark = 0
    best = -1
    one = np.uint64(1)
    scratch = np.zeros(nw, dtype=np.uint64)
    memo = np.zeros(nw, dtype=np.uint64)
    lmem = np.zeros((cap, nw), dtype=np.uint64)  # ng-memory part of the mask
    gnx = np.empty(cap, dtype=np.int64)  # next label of the same group
    # groups: the labels of one vertex with one ng-memory, found through a hash table
    slots = np.full(1 << 12, -1, dtype=np.int64)
    gv = np.empty(1 << 11, dtype=np.int64)
    gkey = np.zeros((1 << 11, nw), dtype=np.uint64)
    ghead = np.empty(1 << 11, dtype=np.int64)
    n_groups = 0
    work = np.zeros(1, dtype=np.int64)  # labels visited by dominance checks
    outside, ngp, ngl = outside_tables(cum, ng, bprof)

    t0 = opn[src]
    r = unreach_count(thr, src, t0)
    lv[0] = src
    lt[0] = t0
    lp[0] = 0.0
    lbnd[0] = np.inf
    par[0] = -1
    qnx[0] = -1
    nxt[0] = -1
    alive[0] = True
    for w in range(nw):
        lm[0, w] = cum[src, r, w]
    head[src] = 0
    qhead[t0 >> qshift] = 0
    n_lab = 1
    pops = 0
    status = DONE
    q = t0 >> qshift
    while q < qhead.shape[0]:
        lab = qhead[q]
        if lab < 0:
            q += 1
            continue
        qhead[q] = qnx[lab]
        if not alive[lab] or lbnd[lab] < lb + gap:
            continue
        pops += 1
        if pops % _CHECK_EVERY == 0 and clock() > deadline:
            status = TIMEOUT
            break
        v = lv[lab]
        t = lt[lab]
        p = lp[lab]
        for e in range(succ_ptr[v], succ_ptr[v + 1]):
            j = succ[e]
            if j != snk and (lm[lab, j >> 6] >> np.uint64(j & 63)) & one:
                continue
            a = t + dur[v, j]
            if a < opn[j]:
                a = opn[j]
            if a > cls[j] or a > tstop:
                continue
            p2 = p + prof[j]
            for w in range(nc):
                st = lc[lab, w] & cut_m[j, w]
                state[w] = st ^ cut_s[j, w]
                p2 -= sig_of(st & cut_s[j, w], w * 64, sig)
            if j == snk:
                bnd = p2
            else:
                bnd = np.inf
                if use_tab:
                    bnd = p2 + completion(tab, j, a, horizon, width, prof)
            if bnd < lb + gap:
                continue
            g = -1
            if j != snk:
                r = unreach_count(thr, j, a)
                for w in range(nw):
                    memo[w] = lmem[lab, w] & ng[j, w]
                memo[j >> 6] |= one << np.uint64(j & 63)
                for w in range(nw):
                    scratch[w] = memo[w] | cum[j, r, w]
                if not use_tab:
                    # without a table: at most the customers neither remembered nor out of reach
                    bnd = p2 + profit_outside(outside, ngp, ngl, cum, j, r, memo, bprof)
                    if bnd < lb + gap:
                        continue
                g = find_group(slots, gv, gkey, j, memo)
                if g >= 0 and dominance(ghead, g, gnx, alive, lt, lp, lm, lc, sig, a, p2,
                                         scratch, state, cap_max, work):
                    continue
                if dominance(head, j, nxt, alive, lt, lp, lm, lc, sig, a, p2, scratch, state,
                             scan, work):
                    continue
                if g < 0:
                    slot = -1 - g
                    if n_groups == gv.shape[0]:
                        gv = grow1(gv, 2 * n_groups)
                        ghead = grow1(ghead, 2 * n_groups)
                        gkey = grow2(gkey, 2 * n_groups)
                    g = n_groups
                    n_groups += 1
                    gv[g] = j
                    ghead[g] = -1
                    for w in range(nw):
                        gkey[g, w] = memo[w]
                    slots[slot] = g
                    if 2 * n_groups > slots.shape[0]:
                        slots = rehash(slots, gv, gkey, n_groups)
            if n_lab >= cap:
                if cap >= cap_max:
                    status = FULL
                    break
                cap = min(2 * cap, cap_max)
                lv = grow1(lv, cap)
                lt = grow1(lt, cap)
                lp = grow1(lp, cap)
                lbnd = grow1(lbnd, cap)
                par = grow1(par, cap)
                nxt = grow1(nxt, cap)
                qnx = grow1(qnx, cap)
                alive = grow1(alive, cap)
                lm = grow2(lm, cap)
                lmem = grow2(lmem, cap)
                lc = grow2(lc, cap)
                gnx = grow1(gnx, cap)
            s = n_lab
            n_lab += 1
            lv[s] = j
            lt[s] = a
            lp[s] = p2
            lbnd[s] = bnd
            par[s] = lab
            if j == snk:
                alive[s] = False
                mark += 1
                if is_elementary(par, lv, s, stamp, mark):
                    if collect > 0:
                        if n_found == found.shape[0]:
                            found = grow1(found, 2 * n_found)
                        found[n_found] = s
                        n_found += 1
                        if n_found >= collect:
                            status = ENOUGH
                            break
                        continue
                    lb = p2
                    best = s
                    if lb + gap > ub:
                        break
                else:
                    if n_sinks == sinks.shape[0]:
                        sinks = grow1(sinks, 2 * n_sinks)
                    sinks[n_sinks] = s
                    n_sinks += 1
                continue
            alive[s] = True
            for w in range(nw):
                lm[s, w] = scratch[w]
                lmem[s, w] = memo[w]
            for w in range(nc):
                lc[s, w] = state[w]
            nxt[s] = head[j]
            head[j] = s
            gnx[s] = ghead[g]
            ghead[g] = s
            qnx[s] = qhead[a >> qshift]
            qhead[a >> qshift] = s
            k = a // width
            if k >= own.shape[1]:
                k = own.shape[1] - 1
            if p2 > own[j, k]:
                own[j, k] = p2
        if status != DONE or lb + gap > ub:
            break
    return (status, lb, best, sinks, n_sinks, lv, lp, par, n_lab, own, pops, work[0], found,
            n_found, lt, lmem, lc, alive)


follow_callees(__name__, globals())
