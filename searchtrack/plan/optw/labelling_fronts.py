r"""Time-sorted label fronts of the OPTW labelling kernel, one per same-memory group.

The labels of one vertex ``v`` with one ng-memory ``M`` (a *group*, found through the hash table
of :mod:`searchtrack.plan.optw.labelling_primitives`) have masks ``M ∪ U(t)``, where ``U(t)`` —
the customers out of reach from ``v`` after time ``t`` (Feillet et al. 2004) — grows with ``t``.
Within a group, ``t_a ≤ t_b`` therefore implies ``mask_a ⊆ mask_b``, and dominance reduces to
time and profit (plus the subset-row cut penalty when cuts are priced). Each group keeps its
labels' times and profits in a contiguous segment of one pool, sorted by time:

- without cuts the segment is a Pareto front (times and profits both strictly increasing), so a
  new label is dominated exactly when its predecessor in time order has at least its profit (a
  binary search), and the labels it dominates are a run of consecutive entries;
- with cuts the segment is only sorted; a check scans the earlier (or later) part, reading the
  cut states of the few labels that pass the time-and-profit test.

Across groups of one vertex the same fronts serve: a label of group ``M'`` can dominate a new
label with mask ``K`` only if ``M' ⊆ K``, and the new label (ng-memory ``M``) can dominate the
labels of group ``M'`` from the time on when ``M \ M'`` is out of reach. A segment that fills is
moved to the pool's end at twice its size; dead labels leave their segment.
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
def front_kill(ft, fp, fl, alive, lc, sig, start, length, t0, p, state, work):  # type: ignore[no-untyped-def]
    """Mark dead and remove the labels of the segment ``[start, start + length)`` whose time is
    ``t0`` or later and whose profit ``(p, state)`` covers; returns the segment's new length.

    ``t0`` is the earliest time at which the new label's mask is within the segment's masks
    (its own group: the new label's time).
    """
    end = start + length
    lo = _after(ft, start, end, t0, False)
    if lo == end:
        return length
    if lc.shape[1] == 0:
        # a Pareto front: the dominated labels are the run from ``lo`` of profit at most ``p``
        hi = lo
        while hi < end and fp[hi] <= p:
            alive[fl[hi]] = False
            hi += 1
        work[0] += hi - lo + 1
        if hi == lo:
            return length
        for i in range(hi, end):
            ft[lo + i - hi] = ft[i]
            fp[lo + i - hi] = fp[i]
            fl[lo + i - hi] = fl[i]
        return length - (hi - lo)
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
    return length - (end - k)


@njit(cache=True, inline="always")
def front_put(ft, fp, fl, gstart, glen, gcap, g, used, t, p, s):  # type: ignore[no-untyped-def]
    """Insert label ``s`` = ``(t, p)`` into group ``g``'s segment in time order (before the
    labels of equal time); returns the pool's new used length.

    A full segment moves to the pool's end and takes :func:`front_room` ``(gcap[g])`` entries
    there, which the caller makes sure fit.
    """
    start = gstart[g]
    end = start + glen[g]
    lo = _after(ft, start, end, t, False)
    if glen[g] >= gcap[g]:
        cap = front_room(gcap[g])
        for i in range(start, lo):
            ft[used + i - start] = ft[i]
            fp[used + i - start] = fp[i]
            fl[used + i - start] = fl[i]
        for i in range(lo, end):
            ft[used + i - start + 1] = ft[i]
            fp[used + i - start + 1] = fp[i]
            fl[used + i - start + 1] = fl[i]
        lo = used + lo - start
        gstart[g] = used
        gcap[g] = cap
        used += cap
    else:
        for i in range(end - 1, lo - 1, -1):
            ft[i + 1] = ft[i]
            fp[i + 1] = fp[i]
            fl[i + 1] = fl[i]
    ft[lo] = t
    fp[lo] = p
    fl[lo] = s
    glen[g] += 1
    return used


follow_callees(__name__, globals())
