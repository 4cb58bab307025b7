"""The expansion loop of the OPTW labelling kernel (:mod:`searchtrack.plan.optw.labelling_kernels`).

:func:`expand` pops labels in order of time and extends them along the feasible arcs, with the
bounds and dominance rules the kernel's docstring states. It never grows an array: when the next
label, group, front entry or path would not fit, it saves where it stood in the state vector and
returns :data:`ROOM`; the kernel grows the arrays and calls it again, and it resumes with the
same candidate arc. Every array is allocated by the caller and none is reassigned, so the loop is
compiled without numba's reference counting
(:data:`searchtrack.core.kernel_cache.NO_REFCOUNTS`).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from searchtrack.core.kernel_cache import NO_REFCOUNTS, follow_callees
from searchtrack.plan.optw.labelling_fronts import (
    front_dominated,
    front_kill,
    front_put,
    front_room,
)
from searchtrack.plan.optw.labelling_primitives import (
    clock,
    completion,
    find_group,
    is_elementary,
    profit_outside,
    sig_of,
    unreach_count,
)

DONE = 0  # the pass finished: every label was expanded or pruned
TIMEOUT = 1  # the deadline passed
FULL = 2  # the label store reached its capacity
ENOUGH = 3  # collect mode: the asked number of elementary paths was found
ROOM = 4  # an array is full: grow it and call again

# slots of the state vector ``st``
Q, N_LAB, POPS, N_GROUPS, USED, BEST, N_SINKS, N_FOUND, MARK, CUR, EDGE, STATUS = range(12)
STATE = 12

_CHECK_EVERY = 64  # expanded labels between two clock reads


@njit(cache=True, **NO_REFCOUNTS)
def expand(  # type: ignore[no-untyped-def]
    dur, succ_ptr, succ, opn, cls, prof, ng, thr, cum, gone, snk, tab, use_tab, horizon, width,
    qshift, ub, gap, cap_max, deadline, collect, bprof, cut_s, cut_m, sig, tstop,
    outside, ngp, ngl,
    lv, lt, lp, lbnd, par, qnx, alive, lm, lmem, lc, qhead, own, sinks, found, stamp,
    slots, gv, gkey, gstart, glen, gcap, vhead, gnext, ft, fp, fl, st, lbv, work, state, scratch,
    memo,
):
    """Run the expansion loop from the state ``st`` (and best profit ``lbv[0]``) until the pass
    ends (``st[STATUS]`` and the return value: DONE, TIMEOUT, FULL or ENOUGH) or an array is
    full (ROOM: ``st[CUR]``, ``st[EDGE]`` hold the label and arc to resume with)."""
    nw = ng.shape[1]
    nc = cut_s.shape[1]
    one = np.uint64(1)
    cap = lv.shape[0]
    q = st[Q]
    n_lab = st[N_LAB]
    pops = st[POPS]
    n_groups = st[N_GROUPS]
    used = st[USED]
    best = st[BEST]
    n_sinks = st[N_SINKS]
    n_found = st[N_FOUND]
    mark = st[MARK]
    lab = st[CUR]
    e0 = st[EDGE]
    lb = lbv[0]
    status = DONE
    while True:
        if lab < 0:
            if q >= qhead.shape[0]:
                break
            lab = qhead[q]
            if lab < 0:
                q += 1
                continue
            qhead[q] = qnx[lab]
            if not alive[lab] or lbnd[lab] < lb + gap:
                lab = -1
                continue
            pops += 1
            if pops % _CHECK_EVERY == 0 and clock() > deadline:
                status = TIMEOUT
                break
            e0 = succ_ptr[lv[lab]]
        v = lv[lab]
        t = lt[lab]
        p = lp[lab]
        for e in range(e0, succ_ptr[v + 1]):
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
                s0 = lc[lab, w] & cut_m[j, w]
                state[w] = s0 ^ cut_s[j, w]
                p2 -= sig_of(s0 & cut_s[j, w], w * 64, sig)
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
                # every group at ``j`` whose memory lies within the new mask may dominate it
                # (its own group first: the likeliest to)
                beaten = g >= 0 and front_dominated(ft, fp, fl, lc, sig, gstart[g], glen[g], a,
                                                    p2, state, work)
                h = vhead[j]
                while h >= 0 and not beaten:
                    work[0] += 1
                    within = h != g
                    for w in range(nw):
                        if gkey[h, w] & ~scratch[w]:
                            within = False
                            break
                    beaten = within and front_dominated(ft, fp, fl, lc, sig, gstart[h], glen[h],
                                                        a, p2, state, work)
                    h = gnext[h]
                if beaten:
                    continue
            if n_lab >= cap:
                if cap >= cap_max:
                    status = FULL
                    break
                status = ROOM
            elif j == snk:
                if n_sinks >= sinks.shape[0] or n_found >= found.shape[0]:
                    status = ROOM
            elif g < 0:
                if n_groups >= gv.shape[0] or 2 * (n_groups + 1) > slots.shape[0] or \
                        used + front_room(0) > ft.shape[0]:
                    status = ROOM
            elif used + front_room(gcap[g]) > ft.shape[0] and glen[g] >= gcap[g]:
                status = ROOM
            if status == ROOM:
                e0 = e
                break
            if g < 0 and j != snk:
                slot = -1 - g
                g = n_groups
                n_groups += 1
                gv[g] = j
                gstart[g] = used
                glen[g] = 0
                gcap[g] = 0
                for w in range(nw):
                    gkey[g, w] = memo[w]
                slots[slot] = g
                gnext[g] = vhead[j]
                vhead[j] = g
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
                    sinks[n_sinks] = s
                    n_sinks += 1
                continue
            alive[s] = True
            for w in range(nw):
                lm[s, w] = scratch[w]
                lmem[s, w] = memo[w]
            for w in range(nc):
                lc[s, w] = state[w]
            # the labels at ``j`` the new one dominates: in group ``h`` those from the time on
            # when the customers it remembers and ``h`` does not are out of reach
            h = vhead[j]
            while h >= 0:
                if glen[h] > 0 and ft[gstart[h] + glen[h] - 1] >= a:
                    t0 = a
                    for e2 in range(ngp[j], ngp[j + 1]):
                        c = ngl[e2]
                        w = c >> 6
                        bit = np.uint64(c & 63)
                        if (memo[w] >> bit) & one and not (gkey[h, w] >> bit) & one and \
                                gone[j, c] >= t0:
                            t0 = gone[j, c] + 1
                    if t0 <= ft[gstart[h] + glen[h] - 1]:
                        glen[h] = front_kill(ft, fp, fl, alive, lc, sig, gstart[h], glen[h], t0,
                                             p2, state, work)
                h = gnext[h]
            used = front_put(ft, fp, fl, gstart, glen, gcap, g, used, a, p2, s)
            qnx[s] = qhead[a >> qshift]
            qhead[a >> qshift] = s
            k = a // width
            if k >= own.shape[1]:
                k = own.shape[1] - 1
            if p2 > own[j, k]:
                own[j, k] = p2
        if status != DONE or lb + gap > ub:
            break
        lab = -1
    st[Q] = q
    st[N_LAB] = n_lab
    st[POPS] = pops
    st[N_GROUPS] = n_groups
    st[USED] = used
    st[BEST] = best
    st[N_SINKS] = n_sinks
    st[N_FOUND] = n_found
    st[MARK] = mark
    st[CUR] = lab
    st[EDGE] = e0
    st[STATUS] = status
    lbv[0] = lb
    return status


follow_callees(__name__, globals())
