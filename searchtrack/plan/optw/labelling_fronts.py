"""Time-sorted label fronts of the OPTW labelling kernel, one per same-memory group.

The labels of one vertex ``v`` with one ng-memory ``M`` (a *group*, found through the hash table
of :mod:`searchtrack.plan.optw.labelling_primitives`) have masks ``M ∪ U(t)``, where ``U(t)`` —
the customers out of reach from ``v`` after time ``t`` (Feillet et al. 2004) — grows with ``t``.
Within a group, ``t_a ≤ t_b`` therefore implies ``mask_a ⊆ mask_b``, and dominance reduces to
time and profit (plus the subset-row cut penalty when cuts are priced). Each group keeps its
labels' times and profits in a contiguous segment of one pool, sorted by time:

- without cuts the segment is a Pareto front (times and profits both strictly increasing), so a
  new label is dominated exactly when its predecessor in time order has at least its profit (a
  binary search), and the labels it dominates are the run that follows it;
- with cuts the segment is only sorted; a check scans the earlier (or later) part, reading the
  cut states of the few labels that pass the time-and-profit test.

A segment that fills is moved to the pool's end at twice its size. Labels killed by another
group's label stay in the segment: dominance is transitive, so they remain valid witnesses.
"""

from __future__ import annotations

from numba import njit

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.labelling_primitives import cut_penalty

_FIRST = 4  # entries of a new segment


@njit(cache=True, inline="always")
def _after(ft, lo, hi, t, strict):  # type: ignore[no-untyped-def]
    """First index of ``ft[lo:hi]`` whose time exceeds ``t`` (``strict``) or reaches it."""
    while lo < hi:
        mid = (lo + hi) >> 1
        if ft[mid] < t or (strict and ft[mid] == t):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, inline="always")
def front_room(cap):  # type: ignore[no-untyped-def]
    """Pool entries a full segment of ``cap`` entries takes when it moves (``cap = 0``: a new
    group's first segment)."""
    return max(_FIRST, 2 * cap)


@njit(cache=True, inline="always")
def front_dominated(ft, fp, fl, lc, sig, start, length, t, p, state, work):  # type: ignore[no-untyped-def]
    """True when a label of the segment ``[start, start + length)`` dominates ``(t, p, state)``
    (equal labels count as dominating the newcomer)."""
    end = _after(ft, start, start + length, t, True)
    if lc.shape[1] == 0:
        work[0] += 1
        return end > start and fp[end - 1] >= p
    for i in range(end - 1, start - 1, -1):
        work[0] += 1
        if fp[i] >= p and fp[i] - cut_penalty(lc, fl[i], state, sig, True) >= p:
            return True
    return False


@njit(cache=True, inline="always")
def front_insert(ft, fp, fl, gstart, glen, gcap, g, used, alive, lc, sig, t, p, s, state, work):  # type: ignore[no-untyped-def]
    """Add label ``s`` = ``(t, p, state)``, not dominated, to group ``g``'s segment, marking dead
    and removing the labels it dominates.

    Returns the pool's new used length. A segment that must move takes
    :func:`front_room` ``(gcap[g])`` entries at the pool's end, which the caller makes sure fit.
    """
    start = gstart[g]
    length = glen[g]
    end = start + length
    lo = _after(ft, start, end, t, False)  # the insertion point
    if lc.shape[1] == 0:
        # the dominated labels are the run after ``lo`` with at most profit ``p``
        hi = lo
        while hi < end and fp[hi] <= p:
            alive[fl[hi]] = False
            hi += 1
        work[0] += hi - lo + 1
        tail = hi
    else:
        # compact the survivors of ``[lo, end)`` to ``[lo, end)``
        k = lo
        for i in range(lo, end):
            work[0] += 1
            if p >= fp[i] and p - cut_penalty(lc, fl[i], state, sig, False) >= fp[i]:
                alive[fl[i]] = False
            else:
                ft[k] = ft[i]
                fp[k] = fp[i]
                fl[k] = fl[i]
                k += 1
        end = k
        tail = lo
    # the survivors ``[tail, end)`` move to ``[lo + 1, ...)`` and the new label goes to ``lo``
    rest = end - tail
    new_len = lo - start + 1 + rest
    if new_len > gcap[g]:
        cap = front_room(gcap[g])
        dst = used
        used += cap
        for i in range(start, lo):
            ft[dst + i - start] = ft[i]
            fp[dst + i - start] = fp[i]
            fl[dst + i - start] = fl[i]
        lo = dst + lo - start
        for i in range(rest):
            ft[lo + 1 + i] = ft[tail + i]
            fp[lo + 1 + i] = fp[tail + i]
            fl[lo + 1 + i] = fl[tail + i]
        gstart[g] = dst
        gcap[g] = cap
    elif tail > lo + 1:
        for i in range(rest):
            ft[lo + 1 + i] = ft[tail + i]
            fp[lo + 1 + i] = fp[tail + i]
            fl[lo + 1 + i] = fl[tail + i]
    elif tail < lo + 1:
        for i in range(rest - 1, -1, -1):
            ft[lo + 1 + i] = ft[tail + i]
            fp[lo + 1 + i] = fp[tail + i]
            fl[lo + 1 + i] = fl[tail + i]
    ft[lo] = t
    fp[lo] = p
    fl[lo] = s
    glen[g] = new_len
    return used


follow_callees(__name__, globals())
