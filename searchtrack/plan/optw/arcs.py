"""Preprocessing for the exact OPTW models: the arc graph and time-window relations."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.plan.optw.reach import reach

_log = logging.getLogger("searchtrack.plan.optw.arcs")

NEVER = np.iinfo(np.int64).max // 4
"""Gap marking "cannot follow"."""


@dataclass(frozen=True, eq=False)
class ArcGraph:
    """Customers worth modelling and the arcs some feasible route can use.

    Node 0 is the depot (the start as a tail, the end as a head); node ``k ≥ 1`` is vertex
    ``vertices[k - 1]``. ``delta[a]`` is the least time from the service start at the tail to the
    service start at the head (to the finish for arcs into node 0); ``weight[a]`` adds the waiting
    the windows force. ``earliest``/``latest`` bound the service start of each node (node 0:
    departure and latest finish).
    """

    vertices: NDArray[np.intp]
    earliest: NDArray[np.int64]
    latest: NDArray[np.int64]
    tails: NDArray[np.intp]
    heads: NDArray[np.intp]
    delta: NDArray[np.int64]
    weight: NDArray[np.int64]
    empty_ok: bool

    @property
    def size(self) -> int:
        """Number of nodes, depot included."""
        return int(self.vertices.size) + 1


def arc_graph(instance: OPTWInstance) -> ArcGraph:
    """Eliminate unreachable customers and arcs that no feasible route can use."""
    inst = instance
    r = reach(inst)
    verts = r.useful
    k = verts.size
    dep, limit = inst.departure, inst.latest_finish
    s = inst.service.astype(np.int64)
    earliest = np.concatenate(([dep], r.earliest[verts])).astype(np.int64)
    latest = np.concatenate(([limit], r.latest[verts])).astype(np.int64)
    # Customer-to-customer arcs straight from reach.
    sub = r.arc_ok[np.ix_(verts, verts)]
    ti, hi = np.nonzero(sub)
    tails = [ti + 1]
    heads = [hi + 1]
    delta = [s[verts[ti]] + inst.travel[verts[ti], verts[hi]]]
    # Start to customer.
    d0 = s[inst.start] + inst.travel[inst.start, verts]
    ok0 = np.maximum(dep + d0, inst.open[verts]) <= latest[1:]
    tails.append(np.zeros(int(ok0.sum()), dtype=np.intp))
    heads.append(np.flatnonzero(ok0) + 1)
    delta.append(d0[ok0])
    # Customer to end (or stop, for an open end).
    d1 = s[verts] if inst.end is None else s[verts] + inst.travel[verts, inst.end]
    ok1 = earliest[1:] + d1 <= limit
    tails.append(np.flatnonzero(ok1) + 1)
    heads.append(np.zeros(int(ok1.sum()), dtype=np.intp))
    delta.append(d1[ok1])
    if inst.end is None:
        empty_ok = dep + int(s[inst.start]) <= limit
    else:
        empty_ok = dep + int(s[inst.start]) + int(inst.travel[inst.start, inst.end]) <= limit
    t = np.concatenate(tails).astype(np.intp)
    h = np.concatenate(heads).astype(np.intp)
    d = np.concatenate(delta).astype(np.int64)
    if t.size:  # no route finishes later than its last service allows (finite for an open end)
        into = h == 0
        latest[0] = min(limit, int(np.max(latest[t[into]] + d[into], initial=dep)))
    tail_latest = np.where(t == 0, dep, latest[t])
    w = np.where(h == 0, d, np.maximum(d, earliest[h] - tail_latest))
    _log.debug("arc graph: %d of %d customers, %d arcs", k, inst.customers.size, t.size)
    return ArcGraph(verts, earliest, latest, t, h, d, w, empty_ok)


def follow_gaps(instance: OPTWInstance, g: ArcGraph) -> NDArray[np.int64]:
    """``E[a, b]``: earliest service start at node ``b`` on a route that serves ``a`` before it.

    Time-window aware forward search from every customer ``a`` started at ``earliest[a]``
    (waiting allowed, so arrival times are FIFO); ``NEVER`` where ``b`` cannot follow ``a``.
    Only customer nodes ``1..K`` are filled.
    """
    k = g.size - 1
    inst = instance
    v = g.vertices
    step = inst.service[v][:, None] + inst.travel[np.ix_(v, v)]
    np.fill_diagonal(step, NEVER)
    opn, lat = inst.open[v], g.latest[1:]
    out = np.full((g.size, g.size), NEVER, dtype=np.int64)
    for a in range(k):
        best = np.full(k, NEVER, dtype=np.int64)
        done = np.zeros(k, dtype=bool)
        best[a] = g.earliest[a + 1]
        while True:
            cand = np.where(done, NEVER, best)
            u = int(np.argmin(cand))
            if cand[u] >= NEVER:
                break
            done[u] = True
            arr = np.maximum(best[u] + step[u], opn)
            ok = (arr <= lat) & ~done & (arr < best)
            best = np.where(ok, arr, best)
        best[a] = NEVER  # a itself does not follow a
        out[a + 1, 1:] = best
    return out


def shortest_gaps(instance: OPTWInstance, g: ArcGraph) -> NDArray[np.int64]:
    """``D[a, b]``: least service-start-to-service-start time from ``a`` to ``b`` (any path)."""
    v = g.vertices
    d = (instance.service[v][:, None] + instance.travel[np.ix_(v, v)]).astype(np.int64)
    for m in range(v.size):
        d = np.minimum(d, d[:, m : m + 1] + d[m : m + 1, :])
    return d
