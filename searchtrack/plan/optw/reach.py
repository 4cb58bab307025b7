"""Reachability preprocessing shared by the OPTW solvers (not by the validator).

Earliest service start ``earliest[v]`` (from the start vertex) and latest service start
``latest[v]`` (still able to finish in time) are exact shortest-path bounds over the windowed graph;
they do not assume the triangle inequality, which truncated distances break.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.plan.optw.instance import OPTWInstance

_NEVER = np.iinfo(np.int64).max // 4


@dataclass(frozen=True, eq=False)
class Reach:
    """Time bounds per vertex and the arcs that can lie on some feasible route."""

    earliest: NDArray[np.int64]
    latest: NDArray[np.int64]
    vertex_ok: NDArray[np.bool_]
    arc_ok: NDArray[np.bool_]

    @property
    def useful(self) -> NDArray[np.intp]:
        """Customers that some feasible route can visit."""
        return np.flatnonzero(self.vertex_ok)


def reach(inst: OPTWInstance) -> Reach:
    """Compute earliest/latest service starts, reachable customers and feasible arcs."""
    n = inst.n
    t, s, o, c = inst.travel, inst.service, inst.open, inst.close
    customers = np.zeros(n, dtype=bool)
    customers[inst.customers] = True
    # Forward Dijkstra on earliest service start (waiting allowed, so arrival is FIFO).
    earliest = np.full(n, _NEVER, dtype=np.int64)
    earliest[inst.start] = inst.departure
    done = np.zeros(n, dtype=bool)
    for _ in range(n):
        cand = np.where(done, _NEVER, earliest)
        u = int(np.argmin(cand))
        if cand[u] >= _NEVER:
            break
        done[u] = True
        if u != inst.start and not customers[u]:
            continue  # routes stop at the end vertex
        arr = np.maximum(earliest[u] + s[u] + t[u], o)
        ok = customers & (arr <= c) & ~done
        earliest = np.where(ok & (arr < earliest), arr, earliest)
    # Backward Dijkstra on latest service start that still reaches the end in time.
    limit = inst.latest_finish
    latest = np.full(n, -_NEVER, dtype=np.int64)
    if inst.end is None:
        latest[customers] = np.minimum(c[customers], limit - s[customers])
        latest[inst.start] = min(int(c[inst.start]), limit - int(s[inst.start]))
    else:
        latest[inst.end] = min(int(c[inst.end]), limit)
    done[:] = False
    for _ in range(n):
        cand = np.where(done, -_NEVER, latest)
        w = int(np.argmax(cand))
        if cand[w] <= -_NEVER:
            break
        done[w] = True
        if not customers[w] and w != inst.end and not (inst.end is None and w == inst.start):
            continue
        dep = latest[w] - t[:, w] - s
        lat = np.minimum(dep, c)
        ok = (customers | (np.arange(n) == inst.start)) & ~done & (lat >= o)
        latest = np.where(ok & (lat > latest), lat, latest)
    vertex_ok = customers & (earliest <= latest)
    arc_ok = (earliest[:, None] + s[:, None] + t <= latest[None, :])
    usable = vertex_ok.copy()
    usable[inst.start] = True
    if inst.end is not None:
        usable[inst.end] = True
    arc_ok &= usable[:, None] & usable[None, :]
    np.fill_diagonal(arc_ok, False)
    arc_ok[:, inst.start] = False
    if inst.end is not None:
        arc_ok[inst.end, :] = False
    return Reach(earliest, latest, vertex_ok, arc_ok)
