"""Route enumeration for the team-OPTW branch-and-price: every route within the gap, then a
set packing over them (Baldacci, Christofides & Mingozzi 2008, for the vehicle routing problem).

**The threshold.** Let ``(π, σ)`` be duals of a node's master with the right signs (``π_i ≥ 0``
on the rows of customers not required, ``σ ≥ 0``), ``U`` a proven bound on the best route value
``v_r = Σ_{i∈r} (p_i − π_i) − Σ_c σ_c α_c(r)`` at those duals and ``L = Σ_i π_i + Σ_c σ_c + m·U``
the Lagrangian bound they give. A plan ``x`` of the node collects

    ``z(x) = Σ_{r∈x} v_r + Σ_i π_i·cover_i(x) + Σ_c σ_c·α_c(x)``
    ``≤ v_r + (m − 1)·U + Σ_i π_i + Σ_c σ_c = v_r − U + L``

for each of its routes ``r``: every other route's value is at most ``U``, a plan covers a
customer and a cut at most once, and ``U > 0`` unless the plan has exactly ``m`` routes. A plan
better than the incumbent ``z*`` by at least the profit step ``s`` therefore uses only routes
with ``v_r ≥ θ = U − (L − z* − s)``: a set packing over those routes finds the node's best plan
if it beats ``z*``, and proves ``z*`` optimal for the node if it does not.

**The enumeration** (:func:`enumerate_routes`) is a dynamic program over (customer set, last
customer, cut states), level by level (one more customer per level). A label's value carries
the limited-memory cut costs its visits complete, as in the pricing. Two routes over one set
have one profit and one coverage, so the set packing needs one of them: of the labels with one
set, last customer and cut states only those no other beats in both service start and value are
kept (the earlier reaches every completion the later does, at the same future cut costs). A
label is dropped when its value plus a completion bound stays below ``θ``: the profit table of a
backward labelling pass on the pricing's ng-sets
(:meth:`~searchtrack.plan.optw.bp_pricing.Pricer.completion_table`; cut costs only lower a
completion). The enumeration gives up (``None``) past a label or route budget: on long routes
the number of routes within the gap grows exponentially.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.bp_cuts import masks
from searchtrack.plan.optw.bp_master import Path, Restrictions
from searchtrack.plan.optw.bp_primal import packing
from searchtrack.plan.optw.labelling_core import CAP_MAX, Core, CutMasks, bucket_width
from searchtrack.plan.optw.labelling_primitives import clock, completion, sig_of

if TYPE_CHECKING:
    from searchtrack.plan.optw.bp import Tree

__all__ = ["Duals", "Enumerated", "close_node", "enumerate_routes", "threshold"]

log = logging.getLogger("searchtrack.plan.optw.bp_enumeration")


@dataclass(frozen=True)
class Duals:
    """A node's duals of the right signs with the bounds they gave: ``upper`` (``U``, a proven
    bound on the best route value) and ``lagrangian`` (``L``)."""

    pi: NDArray[np.float64]
    sigma: NDArray[np.float64]  # of the master's first len(sigma) cuts
    upper: float
    lagrangian: float

    def reduced(self, prof: NDArray[np.float64]) -> NDArray[np.float64]:
        """The core profits ``prof`` less ``π`` (0 at the source and the sink)."""
        out = np.zeros(prof.size)
        out[1:-1] = prof[1:-1] - self.pi[1:-1]
        return out


def close_node(tree: Tree, restr: Restrictions, duals: Duals) -> bool:
    """Settle a node by enumeration: list the routes of the node (:class:`Restrictions`) whose
    value reaches :func:`threshold` and solve the set packing over them
    (:func:`~searchtrack.plan.optw.bp_primal.packing`, the node's required customers served).
    Its best plan, if better, is offered to the tree. True when the node is settled: the best
    plan of its subtree is then the incumbent.

    Tried only when the node's gap ``L − z* − s`` is at most half the last gap at which an
    attempt failed (:attr:`Tree.enum_failed`), so failures cost a few tries per run.
    """
    t, step = tree.tuning, tree.step
    gap = duals.lagrangian - tree.value - step
    if t.enum_labels == 0 or tree.value == -math.inf or gap > tree.enum_failed / 2:
        return False
    t0 = time.perf_counter()
    tree.stats["enum_tries"] = tree.stats.get("enum_tries", 0.0) + 1
    settled = _settle(tree, restr, duals)
    if not settled:
        tree.enum_failed = max(gap, 0.0)
    else:
        tree.stats["enum_settled"] = tree.stats.get("enum_settled", 0.0) + 1
    tree.tick("enum_s", t0)
    log.info("enumeration at gap %g (%s): %s in %.2f s", gap, restr,
             "settled" if settled else "failed", time.perf_counter() - t0)
    return settled


def _settle(tree: Tree, restr: Restrictions, duals: Duals) -> bool:
    t, fwd, d = tree.tuning, tree.fwd, tree.deadline
    theta = threshold(duals.upper, duals.lagrangian, tree.value, tree.step)
    cuts = tree.master.cuts[:duals.sigma.size]
    core, idx, table = tree.pricer.completion_table(tree.pricer.node_dur(restr),
                                                    duals.reduced(fwd.prof), theta,
                                                    forbidden=restr.forbidden, cap=CAP_MAX,
                                                    deadline=d)
    if table is None:
        return False
    got = enumerate_routes(core, table, theta, labels=t.enum_labels, routes=t.enum_routes,
                           deadline=d, cuts=masks(cuts, duals.sigma, idx))
    tree.stats["enum_labels"] = tree.stats.get("enum_labels", 0.0) + (
        t.enum_labels if got is None else got.labels)
    if got is None:
        log.info("enumeration over budget (θ = %g)", theta)
        return False
    log.info("enumeration: %d routes, %d labels (θ = %g)", len(got.paths), got.labels, theta)
    tree.stats["enum_routes"] = max(tree.stats.get("enum_routes", 0.0), len(got.paths))
    paths = [tuple(int(idx[v]) for v in p) for p in got.paths]
    m = tree.master
    chosen, proven = packing(paths, [tree.path_profit(p) for p in paths], m.vehicles,
                             m.empty_ok, tree.value, min(t.enum_mip_s, 0.5 * d.remaining()),
                             tree.seed, required=restr.required)
    if chosen is not None:
        tree.offer([paths[k] for k in chosen])
    return proven


def threshold(upper: float, lagrangian: float, incumbent: float, step: float) -> float:
    """``θ = U − (L − z* − s)``: the least value ``v_r`` of a route in a plan that beats the
    incumbent ``z*`` by the profit step ``s`` (by any amount when ``s = 0``; a small
    tolerance then keeps the routes of plans equal to it)."""
    slack = 1e-6 * max(1.0, abs(lagrangian)) if step == 0 else 1e-6
    return upper - (lagrangian - incumbent - step) - slack


@dataclass(frozen=True)
class Enumerated:
    """What :func:`enumerate_routes` found: one path per customer set (``src`` … ``snk``, in
    the graph's vertices) and the labels it made."""

    paths: list[Path]
    labels: int


_MIX = np.uint64(0x9E3779B97F4A7C15)
_CHECK_EVERY = 1024  # labels expanded between two looks at the clock


@njit(cache=True, inline="always")
def _mix(h, word):  # type: ignore[no-untyped-def]
    """Fold a 64-bit word into the hash ``h`` (multiply-xorshift)."""
    h = (h ^ word) * _MIX
    return h ^ (h >> np.uint64(29))


@njit(cache=True)
def _level(  # type: ignore[no-untyped-def]
        bits, last, t, val, lc, dur, succ_ptr, succ, opn, cls, prof, tab, horizon, width, theta,
        snk, cut_s, cut_m, sig, room, deadline):
    """Extend every label of one level by one vertex.

    Returns the number of new labels (``-1`` when over ``room``, ``-2`` past ``deadline``),
    the new labels (sets, last vertices, times, values, cut states, parents, and a hash of set,
    last vertex and cut states) and the labels whose route closes at the sink with a value of
    at least ``theta``. A label's value carries the costs of the subset-row cuts its visits
    complete (limited memory, as in the pricing).
    """
    n_lab, words = bits.shape
    nc = lc.shape[1]
    size = min(room, max(4096, 4 * n_lab))
    nb = np.zeros((size, words), dtype=np.uint64)
    ns = np.zeros((size, nc), dtype=np.uint64)
    ints = np.empty((size, 3), dtype=np.int64)  # last vertex, time, parent
    nv = np.empty(size, dtype=np.float64)
    nh = np.empty(size, dtype=np.uint64)
    fin = np.empty(n_lab, dtype=np.int64)
    state = np.empty(nc, dtype=np.uint64)
    n_fin = 0
    k = 0
    one = np.uint64(1)
    for x in range(n_lab):
        if x % _CHECK_EVERY == 0 and clock() > deadline:
            return -2, nb, ns, ints, nv, nh, fin[:n_fin]
        v = last[x]
        for e in range(succ_ptr[v], succ_ptr[v + 1]):
            j = succ[e]
            w = j >> 6
            b = one << np.uint64(j & 63)
            if j != snk and bits[x, w] & b:
                continue
            a = t[x] + dur[v, j]
            if a < opn[j]:
                a = opn[j]
            if a > cls[j]:
                continue
            if j == snk:
                if val[x] >= theta:
                    fin[n_fin] = x
                    n_fin += 1
                continue
            p2 = val[x] + prof[j]
            rest = completion(tab, j, a, horizon, width, prof)
            if p2 + rest < theta:
                continue  # cut costs only lower it
            for q in range(nc):
                s0 = lc[x, q] & cut_m[j, q]
                state[q] = s0 ^ cut_s[j, q]
                p2 -= sig_of(s0 & cut_s[j, q], q * 64, sig)
            if p2 + rest < theta:
                continue
            if k == size:
                if size >= room:
                    return -1, nb, ns, ints, nv, nh, fin[:n_fin]
                size = min(room, 2 * size)
                nb2 = np.zeros((size, words), dtype=np.uint64)
                nb2[:k] = nb[:k]
                ns2 = np.zeros((size, nc), dtype=np.uint64)
                ns2[:k] = ns[:k]
                ints2 = np.empty((size, 3), dtype=np.int64)
                ints2[:k] = ints[:k]
                nv2 = np.empty(size, dtype=np.float64)
                nv2[:k] = nv[:k]
                nh2 = np.empty(size, dtype=np.uint64)
                nh2[:k] = nh[:k]
                nb, ns, ints, nv, nh = nb2, ns2, ints2, nv2, nh2
            h = np.uint64(j) * _MIX
            for q in range(words):
                word = bits[x, q] | b if q == w else bits[x, q]
                nb[k, q] = word
                h = _mix(h, word)
            for q in range(nc):
                ns[k, q] = state[q]
                h = _mix(h, state[q])
            ints[k, 0] = j
            ints[k, 1] = a
            ints[k, 2] = x
            nv[k] = p2
            nh[k] = h
            k += 1
    return k, nb[:k], ns[:k], ints[:k], nv[:k], nh[:k], fin[:n_fin]


@njit(cache=True, inline="always")
def _same(rows, x, y):  # type: ignore[no-untyped-def]
    """True when rows ``x`` and ``y`` of ``rows`` are equal."""
    for c in range(rows.shape[1]):  # noqa: SIM110 (a loop numba compiles without allocating)
        if rows[x, c] != rows[y, c]:
            return False
    return True


@njit(cache=True)
def _front(order, hashes, bits, last, states, val):  # type: ignore[no-untyped-def]
    """Along ``order`` (by hash, then time, then value down), the labels no earlier label of
    the same set, last vertex and cut states beats in value: the Pareto front of time and value
    of each such group. Labels of one hash are compared key by key (a collision only costs a
    comparison)."""
    keep = np.zeros(order.size, dtype=np.bool_)
    start = 0
    for r in range(order.size):
        x = order[r]
        if r > 0 and hashes[x] != hashes[order[r - 1]]:
            start = r
        beaten = False
        for q in range(start, r):
            y = order[q]
            if not keep[q] or last[y] != last[x] or val[y] < val[x] - 1e-9:
                continue
            if _same(bits, x, y) and _same(states, x, y):
                beaten = True
                break
        keep[r] = not beaten
    return order[keep]


def _kept(bits: NDArray[np.uint64], last: NDArray[np.int64], states: NDArray[np.uint64],
          t: NDArray[np.int64], val: NDArray[np.float64],
          hashes: NDArray[np.uint64]) -> NDArray[np.int64]:
    """The labels no label of equal set, last vertex and cut states beats in time and value."""
    order = np.lexsort([-val, t, hashes])
    return np.asarray(_front(order, hashes, bits, last, states, val), dtype=np.int64)


@njit(cache=True)
def _set_hashes(bits):  # type: ignore[no-untyped-def]
    out = np.empty(bits.shape[0], dtype=np.uint64)
    for x in range(bits.shape[0]):
        h = _MIX
        for q in range(bits.shape[1]):
            h = _mix(h, bits[x, q])
        out[x] = h
    return out


def enumerate_routes(core: Core, table: NDArray[np.float64], theta: float, *, labels: int,
                     routes: int, deadline: Deadline,
                     cuts: CutMasks | None = None) -> Enumerated | None:
    """One path per customer set whose value (``Σ core.prof`` less its cut costs) reaches
    ``theta``.

    Parameters
    ----------
    core
        The node's forward graph, its profits the reduced ones.
    table
        A backward profit table of this graph (:meth:`PassResult.table`): a completion's
        value is at most its entry (cut costs only lower it), so it prunes the labels that
        cannot reach ``theta``.
    theta
        The least value of a route (:func:`threshold`).
    labels, routes
        Budgets: most labels made, most routes found.
    deadline
        When to stop.
    cuts
        The subset-row cuts of positive dual, with those duals.

    Returns
    -------
    Enumerated or None
        ``None`` when a budget or the deadline ran out first.
    """
    words = (core.n + 63) // 64
    width = bucket_width(core.horizon)
    if cuts is None:
        cut_s = cut_m = np.zeros((core.n, 0), dtype=np.uint64)
        sig = np.zeros(0)
    else:
        cut_s, cut_m, sig = cuts.subset, cuts.memory, cuts.dual
    bits = np.zeros((1, words), dtype=np.uint64)
    last = np.array([core.src], dtype=np.int64)
    t = np.array([core.opn[core.src]], dtype=np.int64)
    val = np.zeros(1)
    lc = np.zeros((1, cut_s.shape[1]), dtype=np.uint64)
    parents = np.zeros(0, dtype=np.int64)
    levels: list[tuple[NDArray[np.int64], NDArray[np.int64]]] = []
    ends: list[tuple[int, NDArray[np.int64]]] = []
    sets: list[NDArray[np.uint64]] = []
    made, found = 1, 0
    graph = (core.dur, core.succ_ptr, core.succ, core.opn, core.cls, core.prof, table,
             core.horizon, width, theta, core.snk, cut_s, cut_m, sig)
    while last.size:
        if deadline.expired():
            return None
        count, nb, ns, ints, nv, nh, fin = _level(bits, last, t, val, lc, *graph,
                                                  labels - made, deadline.end)
        if count < 0:
            return None
        nl, nt, npar = ints[:, 0].copy(), ints[:, 1].copy(), ints[:, 2].copy()
        if fin.size:
            ends.append((len(levels), fin))
            sets.append(bits[fin])
            found += fin.size
            if found > 4 * routes:
                return None
        levels.append((last, parents))
        keep = _kept(nb, nl, ns, nt, nv, nh)
        bits, last, t, val, lc, parents = nb[keep], nl[keep], nt[keep], nv[keep], ns[keep], \
            npar[keep]
        made += int(keep.size)
    if not sets:
        return Enumerated([], made)
    allsets = np.concatenate(sets)
    which = np.concatenate([np.full(f.size, lv, dtype=np.int64) for lv, f in ends])
    leaf = np.concatenate([f for _, f in ends])
    hashes = _set_hashes(allsets)
    # one route per set: the front of equal sets with equal (no) last vertex, states and value
    nothing = np.zeros(allsets.shape[0])
    one = _front(np.argsort(hashes, kind="stable"), hashes, allsets, nothing.astype(np.int64),
                 np.zeros((allsets.shape[0], 0), dtype=np.uint64), nothing)
    if one.size > routes:
        return None
    paths = [_path(levels, int(which[i]), int(leaf[i]), core.snk) for i in one.tolist()]
    return Enumerated(paths, made)


def _path(levels: list[tuple[NDArray[np.int64], NDArray[np.int64]]], level: int, x: int,
          snk: int) -> Path:
    """The path of label ``x`` of ``level``, closed at the sink."""
    out = [snk]
    while level >= 0:
        last, parents = levels[level]
        out.append(int(last[x]))
        if level:
            x = int(parents[x])
        level -= 1
    return tuple(out[::-1])


follow_callees(__name__, globals())
