"""Reduced-cost arc fixing for the team-OPTW branch-and-price (Irnich, Desaulniers, Desrosiers
& Hadjar 2010, with the bounds of route enumeration).

With the threshold ``θ`` of :func:`~searchtrack.plan.optw.bp_enumeration.threshold`, every
route of a plan better than the incumbent has a value of at least ``θ`` at the root's duals. An
arc ``i → j`` through which no route reaches ``θ`` can therefore be left out of every pricing
graph for the rest of the search: the plans it could serve cannot beat the incumbent, which
only grows. The bound of a route through ``i → j`` is the best forward label at ``i`` (a
labelling pass on the pricing's ng-sets, bucket by bucket) plus the completion after ``j`` (the
profit table of the backward pass), cut costs left out since they only lower it.

Fixed arcs break the shortcut that lets pricing drop a customer of non-positive reduced profit
(:func:`~searchtrack.plan.optw.bp_pricing.droppable`), so a customer stays droppable only
while every shortcut around it is still an arc (:meth:`Pricer.fix`).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.bp_enumeration import Duals, threshold
from searchtrack.plan.optw.bp_master import Restrictions
from searchtrack.plan.optw.labelling_core import BIG, CAP_MAX, MAX_BUCKETS, Core, run_pass
from searchtrack.plan.optw.labelling_kernels import DONE
from searchtrack.plan.optw.labelling_primitives import completion

if TYPE_CHECKING:
    from searchtrack.plan.optw.bp import Tree

__all__ = ["fix_arcs", "fixable_arcs"]


def fix_arcs(tree: Tree, duals: Duals) -> None:
    """Fix the arcs no route of a better plan can use, at the root's duals ``duals``
    (:meth:`~searchtrack.plan.optw.bp_pricing.Pricer.fix`)."""
    if tree.value == -math.inf:
        return
    t0 = time.perf_counter()
    fwd = tree.fwd
    prof = np.zeros(fwd.n)
    prof[1:-1] = fwd.prof[1:-1] - duals.pi[1:-1]
    core, rev, idx, ng = tree.pricer.graphs(tree.pricer.node_dur(Restrictions()), prof,
                                            frozenset())
    theta = threshold(duals.upper, duals.lagrangian, tree.value, tree.step)
    arcs = fixable_arcs(core, rev, ng, theta, tree.deadline)
    if arcs is not None:
        full = np.zeros((fwd.n, fwd.n), dtype=bool)
        full[np.ix_(idx, idx)] = arcs
        tree.pricer.fix(full)
        tree.stats["fixed_arcs"] = float(tree.pricer.fixed.sum())
    tree.tick("fixing_s", t0)


@njit(cache=True)
def _useless(  # type: ignore[no-untyped-def]
        dur, succ_ptr, succ, opn, cls, prof, own, tab, horizon, width, theta, snk, big):
    """``(n, n)``: True for the arcs through which no route reaches ``theta``."""
    n = dur.shape[0]
    out = np.zeros((n, n), dtype=np.bool_)
    for i in range(n):
        ks = np.flatnonzero(own[i] > -np.inf)
        for e in range(succ_ptr[i], succ_ptr[i + 1]):
            j = succ[e]
            if dur[i, j] >= big:
                continue
            useful = False
            for k in ks:
                a = k * width + dur[i, j]  # the earliest time of bucket k bounds the label's
                if a < opn[j]:
                    a = opn[j]
                if a > cls[j]:
                    break
                rest = 0.0 if j == snk else prof[j] + completion(tab, j, a, horizon, width,
                                                                 prof)
                if own[i, k] + rest >= theta:
                    useful = True
                    break
            out[i, j] = not useful
    return out


def fixable_arcs(fwd: Core, rev: Core, ng: NDArray[np.uint64], theta: float,
                 deadline: Deadline) -> NDArray[np.bool_] | None:
    """The arcs of ``fwd`` (a node's graph on reduced profits) through which no route reaches
    ``theta``, from a forward and a backward labelling pass on the ng-sets ``ng``; ``None``
    when a pass did not finish."""
    bprof = np.maximum(fwd.prof, 0.0)
    passes = [run_pass(core, ng, None, lb=theta, gap=0.0, cap=CAP_MAX, deadline=deadline,
                       collect=1 << 62, bprof=bprof) for core in (fwd, rev)]
    if any(p.code != DONE for p in passes):
        return None
    own = passes[0].own.copy()
    width = max(1, math.ceil((fwd.horizon + 1) / MAX_BUCKETS))  # as the passes
    start = min(int(fwd.opn[fwd.src]) // width, own.shape[1] - 1)
    own[fwd.src, start] = max(own[fwd.src, start], 0.0)  # the empty path at the source
    return np.asarray(_useless(fwd.dur, fwd.succ_ptr, fwd.succ, fwd.opn, fwd.cls, fwd.prof, own,
                               passes[1].table(), fwd.horizon, width, theta, fwd.snk, BIG),
                      dtype=np.bool_)


follow_callees(__name__, globals())
