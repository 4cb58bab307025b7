"""Branching of the team-OPTW branch-and-price (Boussier, Feillet & Gendreau 2007).

A node whose master solution is fractional gets two children:

* on a customer's fractional visit ``y_i = Σ_r a_ir λ_r`` (forbidden / required), ranked by
  ``min(y, 1 − y) × profit``;
* when every visit is integral, on a fractional arc flow ``x_ij`` (forbidden / forced), ranked
  by nearness to ½.

With strong branching (:func:`strong`) the best few of these candidates are tried: each child's
master is re-solved over the pooled columns, without pricing, and the candidate whose children
fall furthest below the parent is chosen, scored by the product of the two falls (Achterberg,
Koch & Martin 2005). A fall is counted at most down to the incumbent, below which a child is
as good as pruned. The pooled master of a child is an estimate only (pricing could raise it), so
it is never taken as the child's bound.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw.bp_master import LPSolution, Master, Restrictions

_FRAC = 1e-6

Branching = tuple[Restrictions, Restrictions]


def candidates(master: Master, profit: NDArray[np.float64], restr: Restrictions,
               lp: LPSolution, most: int) -> list[Branching]:
    """Up to ``most`` ways to branch from a node with restrictions ``restr`` and master solution
    ``lp``, best ranked first (``profit``: by core vertex); empty when nothing is fractional."""
    if np.all(np.abs(lp.values - np.round(lp.values)) <= _FRAC):
        return []
    y = master.visits(lp.values)
    score = np.minimum(y, 1.0 - y) * profit
    score[(y <= _FRAC) | (y >= 1 - _FRAC)] = -1.0
    order = np.argsort(-score, kind="stable")[:most]
    visits = [int(i) for i in order if score[i] > 0]
    if visits:
        return [(restr.child(forbid=i), restr.child(require=i)) for i in visits]
    x = {a: f for a, f in master.arc_flows(lp.values).items() if _FRAC < f < 1 - _FRAC}
    arcs = sorted(x, key=lambda k: (abs(x[k] - 0.5), k))[:most]
    return [(restr.child(no_arc=a), restr.child(arc=a)) for a in arcs]


def branch(master: Master, profit: NDArray[np.float64], restr: Restrictions,
           lp: LPSolution, *, most: int = 1, floor: float = -math.inf,
           deadline: Deadline | None = None) -> tuple[list[Restrictions] | None, int]:
    """The two children to branch into from a node with restrictions ``restr`` and master
    solution ``lp`` (``None`` when that solution is integral), and how many master LPs chose
    them: the best-ranked candidate, or with ``most`` > 1 the best of that many by
    :func:`strong` (``floor``: the incumbent's value; ``deadline`` bounds the probes)."""
    found = candidates(master, profit, restr, lp, max(1, most))
    if not found:
        return None, 0
    k, solved = 0, 0
    if len(found) > 1 and deadline is not None and not deadline.expired():
        master.restrict(restr)  # columns pooled since (plans of the heuristics) obey it too
        k, solved = strong(master, restr, found, lp.objective, floor, deadline)
    return list(found[k]), solved


def pooled_value(master: Master, parent: Restrictions, child: Restrictions,
                 seconds: float) -> float | None:
    """The master optimum over the pooled columns under ``child`` (``parent`` plus one
    decision), the master left as it was under ``parent``; ``None`` if the LP did not finish.

    Only the columns ``parent`` allows and ``child`` does not are bounded to 0, and only the
    newly required rows raised, so a probe costs one pass over the pool and one LP from the
    parent's basis.
    """
    extra = Restrictions(child.forbidden - parent.forbidden, child.required - parent.required,
                         child.no_arcs - parent.no_arcs, child.arcs - parent.arcs)
    off = np.flatnonzero(master.ruled_out(extra) & (master.upper > 0.0))
    master.set_upper(off, 0.0)
    for i in extra.required:
        master.require(i, True)
    try:
        lp = master.solve(seconds)
    finally:
        master.set_upper(off, math.inf)
        for i in extra.required:
            master.require(i, False)
    return None if lp is None else lp.objective


def strong(master: Master, restr: Restrictions, found: list[Branching], parent: float,
           floor: float, deadline: Deadline) -> tuple[int, int]:
    """Index of the candidate in ``found`` with the largest product of its children's falls
    below ``parent`` (each fall at most ``parent − floor``, at least a small positive value),
    and how many master LPs were solved; the first candidate if time runs out."""
    if len(found) < 2:
        return 0, 0
    cap = max(parent - floor, 1e-6) if math.isfinite(floor) else math.inf
    best, best_score, solved = 0, -1.0, 0
    for k, pair in enumerate(found):
        falls = []
        for child in pair:
            z = None if deadline.expired() else pooled_value(master, restr, child,
                                                                   deadline.remaining())
            if z is None:
                return best, solved
            solved += 1
            falls.append(min(max(parent - z, 1e-6), cap))
        score = falls[0] * falls[1]
        if score > best_score:
            best, best_score = k, score
    return best, solved
