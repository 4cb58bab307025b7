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
order of time from a bucket queue (:mod:`searchtrack.plan.optw.labelling_expand`). The labels
of a vertex are grouped by ng-memory (found through a hash table), each group a time-sorted
front (:mod:`searchtrack.plan.optw.labelling_fronts`), and a new label is compared with every
live label at its vertex, group by group. The kernel allocates the label store and grows it
whenever the expansion loop runs out of room.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.labelling_expand import (
    BEST,
    CUR,
    DONE,
    ENOUGH,
    FULL,
    N_FOUND,
    N_GROUPS,
    N_LAB,
    N_SINKS,
    POPS,
    ROOM,
    STATE,
    STATUS,
    TIMEOUT,
    USED,
    Q,
    expand,
)
from searchtrack.plan.optw.labelling_fronts import front_room
from searchtrack.plan.optw.labelling_primitives import (
    grow1,
    grow2,
    outside_tables,
    rehash,
    unreach_count,
)

__all__ = ["DONE", "ENOUGH", "FULL", "TIMEOUT", "label_pass"]


@njit(cache=True)
def label_pass(  # type: ignore[no-untyped-def]
    dur, succ_ptr, succ, opn, cls, prof, ng, thr, cum, gone, src, snk,
    tab, use_tab, horizon, width, qshift, lb, ub, gap, cap_max, deadline, collect, bprof,
    cut_s, cut_m, sig, tstop, room,
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
        ``cum[v, r]`` the mask of the first ``r`` of them; ``gone[v, c]`` the time after which
        customer ``c`` falls out of reach from ``v``.
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
    room
        Labels the store starts with (it doubles when full, up to ``cap_max``); the other
        growing arrays start in proportion. The result does not depend on it.

    Returns
    -------
    tuple
        ``(status, lb, best, sinks, n_sinks, lv, lp, par, n_labels, own, pops, work, found,
        n_found, lt, lmem, lc, alive)``: ``best`` the sink label of the best elementary path
        that beat the given ``lb`` (−1 if none), ``sinks[:n_sinks]`` sink labels of
        non-elementary paths that reached ``lb + gap`` when found, ``own`` this pass's profit
        table (same bucketing as ``tab``), ``pops`` the labels expanded, ``work`` the groups
        and labels visited by dominance checks, ``found[:n_found]`` the sink labels of the
        elementary paths collected (collect mode);
        ``lt``, ``lmem``, ``lc`` and ``alive`` each label's time, ng-memory (own vertex
        included), cut states and whether it is undominated.
    """
    n = dur.shape[0]
    nw = ng.shape[1]
    nc = cut_s.shape[1]
    cap = max(1, min(room, cap_max))
    few = max(2, room >> 4)  # groups, and half the pool entries, to start with
    lv = np.empty(cap, dtype=np.int64)  # vertex
    lt = np.empty(cap, dtype=np.int64)  # time
    lp = np.empty(cap, dtype=np.float64)  # profit
    lbnd = np.empty(cap, dtype=np.float64)  # profit + completion bound
    par = np.empty(cap, dtype=np.int64)  # parent label
    qnx = np.empty(cap, dtype=np.int64)  # next label in the same time bucket
    alive = np.empty(cap, dtype=np.bool_)  # not dominated
    lm = np.zeros((cap, nw), dtype=np.uint64)  # mask: ng-memory and out-of-reach customers
    lmem = np.zeros((cap, nw), dtype=np.uint64)  # ng-memory part of the mask
    lc = np.zeros((cap, nc), dtype=np.uint64)  # subset-row cut states
    vhead = np.full(n, -1, dtype=np.int64)  # the groups of each vertex, linked by ``gnext``
    qhead = np.full((horizon >> qshift) + 1, -1, dtype=np.int64)
    own = np.full(tab.shape, -np.inf)
    sinks = np.empty(max(1, room >> 9), dtype=np.int64)
    found = np.empty(max(1, room >> 9), dtype=np.int64)
    stamp = np.zeros(n, dtype=np.int64)
    # groups: the labels of one vertex with one ng-memory, found through a hash table, each
    # with a time-sorted front in the pool ``ft``, ``fp``, ``fl`` (see labelling_fronts)
    size = 4
    while size < 2 * few:
        size *= 2
    slots = np.full(size, -1, dtype=np.int64)
    gv = np.empty(few, dtype=np.int64)
    gkey = np.zeros((few, nw), dtype=np.uint64)
    gstart = np.empty(few, dtype=np.int64)
    glen = np.empty(few, dtype=np.int64)
    gcap = np.empty(few, dtype=np.int64)
    gnext = np.empty(few, dtype=np.int64)
    ft = np.empty(8 * few, dtype=np.int64)
    fp = np.empty(8 * few, dtype=np.float64)
    fl = np.empty(8 * few, dtype=np.int64)
    work = np.zeros(1, dtype=np.int64)  # groups and labels visited by dominance checks
    outside, ngp, ngl = outside_tables(cum, ng, bprof)

    t0 = opn[src]
    r = unreach_count(thr, src, t0)
    lv[0] = src
    lt[0] = t0
    lp[0] = 0.0
    lbnd[0] = np.inf
    par[0] = -1
    qnx[0] = -1
    alive[0] = True
    for w in range(nw):
        lm[0, w] = cum[src, r, w]
    qhead[t0 >> qshift] = 0
    st = np.zeros(STATE, dtype=np.int64)
    st[Q] = t0 >> qshift
    st[N_LAB] = 1
    st[BEST] = -1
    st[CUR] = -1
    lbv = np.array([lb])
    state = np.zeros(nc, dtype=np.uint64)
    scratch = np.zeros(nw, dtype=np.uint64)
    memo = np.zeros(nw, dtype=np.uint64)
    while expand(dur, succ_ptr, succ, opn, cls, prof, ng, thr, cum, gone, snk, tab, use_tab,
                 horizon, width, qshift, ub, gap, cap_max, deadline, collect, bprof, cut_s, cut_m,
                 sig, tstop, outside, ngp, ngl, lv, lt, lp, lbnd, par, qnx, alive, lm, lmem, lc,
                 qhead, own, sinks, found, stamp, slots, gv, gkey, gstart, glen, gcap, vhead,
                 gnext, ft, fp, fl, st, lbv, work, state, scratch, memo) == ROOM:
        if st[N_LAB] >= lv.shape[0]:
            cap = min(2 * lv.shape[0], cap_max)
            lv = grow1(lv, cap)
            lt = grow1(lt, cap)
            lp = grow1(lp, cap)
            lbnd = grow1(lbnd, cap)
            par = grow1(par, cap)
            qnx = grow1(qnx, cap)
            alive = grow1(alive, cap)
            lm = grow2(lm, cap)
            lmem = grow2(lmem, cap)
            lc = grow2(lc, cap)
        if st[N_SINKS] >= sinks.shape[0]:
            sinks = grow1(sinks, 2 * sinks.shape[0])
        if st[N_FOUND] >= found.shape[0]:
            found = grow1(found, 2 * found.shape[0])
        if st[N_GROUPS] >= gv.shape[0]:
            size = 2 * gv.shape[0]
            gv = grow1(gv, size)
            gstart = grow1(gstart, size)
            glen = grow1(glen, size)
            gcap = grow1(gcap, size)
            gnext = grow1(gnext, size)
            gkey = grow2(gkey, size)
        if 2 * (st[N_GROUPS] + 1) > slots.shape[0]:
            slots = rehash(slots, gv, gkey, st[N_GROUPS])
        # room for the largest segment move (the expansion asks again when that is short)
        need = st[USED] + front_room(int(gcap[: st[N_GROUPS]].max()) if st[N_GROUPS] else 0)
        if need > ft.shape[0]:
            size = 2 * ft.shape[0]
            while size < need:
                size *= 2
            ft = grow1(ft, size)
            fp = grow1(fp, size)
            fl = grow1(fl, size)
    return (st[STATUS], lbv[0], st[BEST], sinks, st[N_SINKS], lv, lp, par, st[N_LAB], own,
            st[POPS], work[0], found, st[N_FOUND], lt, lmem, lc, alive)


follow_callees(__name__, globals())
