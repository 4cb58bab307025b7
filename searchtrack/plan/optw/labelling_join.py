"""Bidirectional labelling: joining the forward and backward half passes at a time split.

Righini & Salani (2006) halve the paths a labelling pass builds: a forward pass makes only labels
whose service start is at most ``t_m``, a backward pass (a forward pass on the reversed graph,
:func:`~searchtrack.plan.optw.labelling_core.core_pair`) only labels whose latest service start
is after ``t_m``, and every path is the join of one label of each over one arc ``i → j``.

* **Where a path is joined.** Split a path after ``i``, its last vertex whose earliest service
  start is at most ``t_m``. Its prefix up to ``i`` is a forward label; its suffix from ``j``
  has earliest, hence latest, starts after ``t_m`` all along (both grow along a path), so it is
  a backward label. A join of forward label ``f`` at ``i`` and backward label ``b`` at ``j`` is
  counted only when the earliest start at ``j``, ``a = max(t_f + d_ij, open_j)``, is after
  ``t_m``, so each path is made once. It is feasible when ``a`` is at most ``b``'s latest start
  ``H − t_b``. Paths whose every earliest start is at most ``t_m`` end in the forward pass.
* **Relaxation.** A join is kept when the two labels' ng-memories are disjoint; an elementary
  path always is. A dominated label's joins are made by its dominator: its memory (with the
  out-of-reach customers) is a subset, so a clash would be a customer the path visits twice or
  cannot reach.
* **Subset-row cuts.** Each half pays ``σ_c`` for each pair of visits to the cut's subset inside
  one memory segment; when both halves end in that segment with an odd count (both state bits
  set), the joined path pays ``σ_c`` once more: ``⌊(k₁ + k₂)/2⌋ = ⌊k₁/2⌋ + ⌊k₂/2⌋ + [k₁, k₂
  odd]``.

:func:`join` returns the elementary paths of a join that reach the target, the best of the
relaxed ones (whose cycles the caller forbids, as in DSSR) and the best value of any join: with
the forward pass's own complete paths, a bound on every path.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.kernel_cache import NO_REFCOUNTS, follow_callees
from searchtrack.plan.optw.labelling_core import Core, PassResult
from searchtrack.plan.optw.labelling_kernels import DONE, TIMEOUT
from searchtrack.plan.optw.labelling_primitives import clock, cut_shared, is_elementary

RELAXED_MAX = 4096  #: relaxed joins kept (the best are the ones whose cycles get forbidden)


@njit(cache=True)
def _by_vertex(bv, bp, balive, nb, n):  # type: ignore[no-untyped-def]
    """The live backward labels grouped by vertex (CSR), each group by decreasing profit."""
    order = np.argsort(-bp[:nb], kind="mergesort")
    ptr = np.zeros(n + 1, dtype=np.int64)
    for x in range(nb):
        if balive[x]:
            ptr[bv[x] + 1] += 1
    for v in range(n):
        ptr[v + 1] += ptr[v]
    fill = ptr[:-1].copy()
    out = np.empty(ptr[n], dtype=np.int64)
    for x in order:
        if balive[x]:
            out[fill[bv[x]]] = x
            fill[bv[x]] += 1
    return ptr, out


@njit(cache=True)
def join_kernel(  # type: ignore[no-untyped-def]
    dur, succ_ptr, succ, opn, horizon, tm,
    fv, ft, fp, fmem, fc, falive, fpar, nf,
    bv, bt, bp, bmem, bc, balive, bpar, nb,
    sig, target, keep, deadline,
):
    """Every join reaching ``target``; see the module docstring.

    Returns ``(status, upper, found_f, found_b, found_v, n_found, rel_f, rel_b, rel_v, n_rel)``:
    the best value of any join (``-inf`` if none reaches ``target``), the label pairs and values
    of the ``keep`` best elementary joins and of up to :data:`RELAXED_MAX` relaxed ones (made
    while no elementary one was known).
    """
    n = dur.shape[0]
    ptr, lab = _by_vertex(bv, bp, balive, nb, n)
    top = np.full(n, -np.inf)
    for v in range(n):
        if ptr[v + 1] > ptr[v]:
            top[v] = bp[lab[ptr[v]]]
    keep = max(keep, 1)
    found_f = np.empty(keep, dtype=np.int64)
    found_b = np.empty(keep, dtype=np.int64)
    found_v = np.empty(keep, dtype=np.float64)
    rel_f = np.empty(RELAXED_MAX, dtype=np.int64)
    rel_b = np.empty(RELAXED_MAX, dtype=np.int64)
    rel_v = np.empty(RELAXED_MAX, dtype=np.float64)
    stamp = np.zeros(n, dtype=np.int64)
    counts = np.zeros(3, dtype=np.int64)  # elementary and relaxed joins kept, stop code
    upper = _join_loop(dur, succ_ptr, succ, opn, horizon, tm, fv, ft, fp, fmem, fc, falive, fpar,
                       nf, bv, bt, bp, bmem, bc, bpar, sig, target, deadline, ptr, lab, top,
                       found_f, found_b, found_v, rel_f, rel_b, rel_v, stamp, counts)
    return (counts[2], upper, found_f, found_b, found_v, counts[0], rel_f, rel_b, rel_v,
            counts[1])


@njit(cache=True, **NO_REFCOUNTS)
def _join_loop(  # type: ignore[no-untyped-def]
    dur, succ_ptr, succ, opn, horizon, tm, fv, ft, fp, fmem, fc, falive, fpar, nf,
    bv, bt, bp, bmem, bc, bpar, sig, target, deadline, ptr, lab, top,
    found_f, found_b, found_v, rel_f, rel_b, rel_v, stamp, counts,
):
    """The loop of :func:`join_kernel` over the arrays it allocated, compiled without numba's
    reference counting; returns the best value of any join and sets ``counts`` to the
    elementary and relaxed joins kept and the stop code (``DONE`` or ``TIMEOUT``)."""
    nw = fmem.shape[1]
    keep = found_f.shape[0]
    n_found = 0
    worst = 0  # slot of the least value while the buffer is full
    n_rel = 0
    mark = 0
    upper = -np.inf
    bar = target  # a join matters only above this
    for f in range(nf):
        if f % 256 == 0 and clock() > deadline:
            counts[0] = n_found
            counts[1] = n_rel
            counts[2] = TIMEOUT
            return upper
        if not falive[f]:
            continue
        i = fv[f]
        t = ft[f]
        p = fp[f]
        for e in range(succ_ptr[i], succ_ptr[i + 1]):
            j = succ[e]
            if p + top[j] < bar:
                continue
            a = t + dur[i, j]
            if a < opn[j]:
                a = opn[j]
            if a <= tm:
                continue
            latest = horizon - a  # a backward label at j must have time at most this
            for k in range(ptr[j], ptr[j + 1]):
                b = lab[k]
                if p + bp[b] < bar:
                    break
                if bt[b] > latest:
                    continue
                clash = False
                for w in range(nw):
                    if fmem[f, w] & bmem[b, w]:
                        clash = True
                        break
                if clash:
                    continue
                # less the pair of visits of a cut's subset that the join completes
                value = p + bp[b] - cut_shared(fc, f, bc, b, sig)
                if value < bar:
                    continue
                if value > upper:
                    upper = value
                mark += 1  # one mark for both halves: no vertex twice in the joined path
                if (is_elementary(fpar, fv, f, stamp, mark)
                        and is_elementary(bpar, bv, b, stamp, mark)):
                    if n_found < keep:
                        slot = n_found
                        n_found += 1
                    elif value > found_v[worst]:
                        slot = worst
                    else:
                        continue
                    found_f[slot] = f
                    found_b[slot] = b
                    found_v[slot] = value
                    if n_found == keep:
                        worst = 0
                        for q in range(1, keep):
                            if found_v[q] < found_v[worst]:
                                worst = q
                        bar = max(target, found_v[worst])
                elif n_found == 0 and n_rel < RELAXED_MAX:
                    rel_f[n_rel] = f
                    rel_b[n_rel] = b
                    rel_v[n_rel] = value
                    n_rel += 1
    counts[0] = n_found
    counts[1] = n_rel
    counts[2] = DONE
    return upper


@dataclass(frozen=True)
class Joined:
    """What :func:`join` found: core paths ``src … snk`` (forward direction)."""

    code: int  #: ``DONE`` or ``TIMEOUT``
    upper: float  #: best value of any join reaching the target (``-inf``: none)
    paths: list[list[int]]  #: the elementary joins reaching the target
    values: list[float]
    relaxed: list[list[int]]  #: relaxed (non-elementary) joins, best first


def split_time(core: Core, share: float = 0.5) -> int:
    """The split time ``t_m`` of a forward core graph: ``share`` of the way from the departure
    to the sink's latest arrival (``0.5``: half-way)."""
    dep, end = int(core.opn[core.src]), int(core.cls[core.snk])
    return dep + int(share * max(0, end - dep))


def backward_stop(core: Core, tm: int) -> int:
    """The backward pass's time limit for split ``t_m``: latest starts after ``t_m``."""
    return core.horizon - tm - 1


def join(core: Core, fwd: PassResult, bwd: PassResult, tm: int, *, target: float,
         keep: int, deadline: Deadline, sig: NDArray[np.float64] | None = None) -> Joined:
    """Join the forward half pass ``fwd`` (made with ``tstop = tm`` on ``core``) and the
    backward one ``bwd`` (on the reversal, ``tstop =`` :func:`backward_stop`) over the arcs of
    ``core``, keeping the ``keep`` best elementary joins; ``sig`` are the cut duals both passes
    priced."""
    duals = np.zeros(64 * fwd.lc.shape[1]) if sig is None else sig
    out = join_kernel(
        core.dur, core.succ_ptr, core.succ, core.opn, core.horizon, tm,
        fwd.lv, fwd.lt, fwd.lp, fwd.lmem, fwd.lc, fwd.alive, fwd.par, fwd.labels,
        bwd.lv, bwd.lt, bwd.lp, bwd.lmem, bwd.lc, bwd.alive, bwd.par, bwd.labels,
        duals, target, keep, deadline.end,
    )
    code, upper, found_f, found_b, found_v, n_found, rel_f, rel_b, rel_v, n_rel = out
    pairs = zip(found_f[:n_found].tolist(), found_b[:n_found].tolist(), strict=True)
    paths = [fwd.path(f) + bwd.path(b)[::-1] for f, b in pairs]
    best = np.argsort(-rel_v[:n_rel], kind="stable")
    relaxed = [fwd.path(int(rel_f[k])) + bwd.path(int(rel_b[k]))[::-1] for k in best.tolist()]
    return Joined(int(code), float(upper) if math.isfinite(upper) else -math.inf, paths,
                  found_v[:n_found].tolist(), relaxed)


follow_callees(__name__, globals())
