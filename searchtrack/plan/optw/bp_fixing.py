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
while every shortcut around it is still an arc (:func:`leave_out`).
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING

import numpy as np
from numba import njit
from numpy.typing import NDArray

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.plan.optw.bp_enumeration import Duals, threshold
from searchtrack.plan.optw.bp_master import Restrictions
from searchtrack.plan.optw.labelling_core import BIG, CAP_MAX, Core, PassResult, bucket_width
from searchtrack.plan.optw.labelling_kernels import DONE
from searchtrack.plan.optw.labelling_primitives import completion

if TYPE_CHECKING:
    from searchtrack.plan.optw.bp import Tree
    from searchtrack.plan.optw.bp_pricing import Pricer

__all__ = ["fix_arcs", "fixable_arcs", "leave_out"]


def fix_arcs(tree: Tree, duals: Duals) -> None:
    """Fix the arcs no route of a better plan can use, at the root's duals ``duals``
    (:func:`leave_out`)."""
    if tree.value == -math.inf:
        return
    t0 = time.perf_counter()
    fwd, pricer = tree.fwd, tree.pricer
    core, rev, idx, ng = pricer.graphs(pricer.node_dur(Restrictions()), duals.reduced(fwd.prof),
                                       frozenset())
    theta = threshold(duals.upper, duals.lagrangian, tree.value, tree.step)
    ahead, back = (pricer.bound_pass(g, ng, theta, CAP_MAX, tree.deadline) for g in (core, rev))
    arcs = fixable_arcs(core, ahead, back, theta)
    if arcs is not None:
        full = np.zeros((fwd.n, fwd.n), dtype=bool)
        full[np.ix_(idx, idx)] = arcs
        leave_out(pricer, full)
        tree.stats["fixed_arcs"] = float(tree.pricer.fixed.sum())
    tree.tick("fixing_s", t0)


def leave_out(pricer: Pricer, arcs: NDArray[np.bool_]) -> None:
    """Leave the arcs ``arcs`` out of every later pricing graph of ``pricer``
    (:attr:`~searchtrack.plan.optw.bp_pricing.Pricer.fixed`); a customer stays droppable only
    while every shortcut ``i → k`` around it (``i → j`` and ``j → k`` arcs) is still an arc,
    else leaving it out could lose a route."""
    pricer.fixed |= arcs
    arc = (pricer.fwd.dur < BIG) & ~pricer.fixed
    src, snk = pricer.fwd.src, pricer.fwd.snk
    for j in np.flatnonzero(pricer.drop_ok).tolist():
        into, out = np.flatnonzero(arc[:, j]), np.flatnonzero(arc[j, :])
        short = arc[np.ix_(into, out)] | (into[:, None] == out[None, :])
        short |= (into[:, None] == src) & (out[None, :] == snk)  # as :func:`droppable`
        pricer.drop_ok[j] = bool(short.all())


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


def fixable_arcs(fwd: Core, ahead: PassResult, back: PassResult,
                 theta: float) -> NDArray[np.bool_] | None:
    """The arcs of ``fwd`` (a node's graph on reduced profits) through which no route reaches
    ``theta``, from a forward and a backward pass on it that kept every label able to reach
    ``theta`` (:meth:`~searchtrack.plan.optw.bp_pricing.Pricer.bound_pass`); ``None`` when a
    pass did not finish."""
    if ahead.code != DONE or back.code != DONE:
        return None
    own = ahead.own.copy()
    width = bucket_width(fwd.horizon)
    start = min(int(fwd.opn[fwd.src]) // width, own.shape[1] - 1)
    own[fwd.src, start] = max(own[fwd.src, start], 0.0)  # the empty path at the source
    return np.asarray(_useless(fwd.dur, fwd.succ_ptr, fwd.succ, fwd.opn, fwd.cls, fwd.prof, own,
                               back.table(), fwd.horizon, width, theta, fwd.snk, BIG),
                      dtype=np.bool_)


follow_callees(__name__, globals())
