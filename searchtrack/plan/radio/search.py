"""Searches of the look-ahead tree and the answer every backend returns (Nguyen et al., eq. 45).

Sequences are ranked lexicographically: a sequence that meets the void constraint beats one
that does not; among those that meet it the larger discounted reward wins; among those that do
not, the smaller total violation ``Σ_t max(0, P_vmin − B_t)`` over the path's poses (the least
violation: a UAV already too close to an object leaves the soonest, where the smallest void
alone would tie every sequence), then the larger reward. Ties go to the first sequence in
enumeration order (node order, then primitive order).

* :func:`exhaustive_search`: depth first over the tree, each node's children expanded together
  (in parts of bounded memory) so a prefix's update is shared by all its sequences. Subtrees
  that cannot beat the incumbent on the constraint are dropped: an infeasible prefix once a
  feasible sequence is known, a prefix whose total violation exceeds the
  least-violating incumbent's otherwise (a prefix's violation bounds its sequences').
* :func:`beam_search`: level by level, keeping the ``width`` best prefixes by the same ranking.

An answer whose best sequence meets the constraint is ``OPTIMAL`` (search complete and exact)
or ``FEASIBLE``. When no sequence meets it the answer is ``INFEASIBLE`` (the exact search saw
every sequence) or ``NO_SOLUTION`` (it did not), with the least-violating plan as its fallback
(:attr:`~searchtrack.core.result.Result.fallback`; ``plan.feasible`` is False) for the caller
to fly at its own risk, no objective, ``stats["infeasible"] = 1`` and
``stats["proven_infeasible"]``; its message says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Result, Status
from searchtrack.core.types import IntArray
from searchtrack.plan.radio.problem import RadioPlan
from searchtrack.plan.radio.tree import Actions, Nodes, Scorer

#: ``(meets the constraint, primary, secondary)``: reward then smallest void when feasible,
#: minus the total violation then reward when not.
Key = tuple[bool, float, float]


@dataclass(frozen=True)
class Best:
    """The best complete sequence so far, its rank and its discounted reward."""

    key: Key
    plan: RadioPlan
    value: float


def key_of(plan: RadioPlan, discount: float, p_void_min: float) -> Key:
    """The rank of a complete plan."""
    value = plan.objective(discount)
    if plan.feasible:
        return True, value, plan.min_void
    return False, -plan.violation(p_void_min), value


def ranking(scorer: Scorer, nodes: Nodes) -> IntArray:
    """Indices of ``nodes`` from best to worst (ties: first index first)."""
    ok = scorer.feasible(nodes)
    low = nodes.min_void
    primary = np.where(ok, nodes.value, -nodes.violation(scorer.settings.p_void_min))
    secondary = np.where(ok, low, nodes.value)
    return np.asarray(np.lexsort((np.arange(nodes.size), -secondary, -primary, ~ok)),
                      dtype=np.int64)


def best_of(scorer: Scorer, leaves: Nodes, incumbent: Best | None) -> Best | None:
    """The better of ``incumbent`` and the best of the complete sequences ``leaves``."""
    if leaves.size == 0:
        return incumbent
    i = int(ranking(scorer, leaves)[0])
    plan = scorer.plan(leaves, i)
    candidate = Best(key_of(plan, scorer.settings.discount, scorer.settings.p_void_min), plan,
                     float(leaves.value[i]))
    if incumbent is None or candidate.key > incumbent.key:
        return candidate
    return incumbent


@dataclass
class Search:
    """What a search found: the best sequence, whether it saw the whole tree (or dropped only
    what provably could not win), nodes expanded, whether it pruned by rank (a heuristic)."""

    best: Best | None = None
    complete: bool = True
    nodes: int = 0
    pruned: bool = False


def _promising(scorer: Scorer, nodes: Nodes, best: Best | None) -> Nodes:
    """``nodes`` without the prefixes that cannot beat ``best`` on the constraint."""
    if best is None:
        return nodes
    if best.key[0]:
        return nodes.take(scorer.feasible(nodes))
    return nodes.take(-nodes.violation(scorer.settings.p_void_min) >= best.key[1])


def exhaustive_search(scorer: Scorer, deadline: Deadline, incumbent: Best | None = None) -> Search:
    """Depth-first search of the whole tree, starting from ``incumbent`` (module docstring)."""
    found = Search(best=incumbent)

    def descend(nodes: Nodes) -> None:
        for part in nodes.chunks(scorer.per_child):
            if deadline.expired():
                found.complete = False
                return
            kids = scorer.expand(part, posterior=part.level + 1 < scorer.horizon)
            found.nodes += kids.size
            kids = _promising(scorer, kids, found.best)
            if kids.level == scorer.horizon:
                found.best = best_of(scorer, kids, found.best)
            elif kids.size:
                descend(kids)
            if not found.complete:
                return

    descend(scorer.root())
    return found


def beam_search(scorer: Scorer, deadline: Deadline, width: int,
                actions: Actions | None = None) -> Search:
    """Level by level, the ``width`` best prefixes kept (all of them when ``width`` is at least
    the level's size: then the search is exact). When the deadline passes, the best prefix is
    finished greedily (width 1), so a plan always comes back."""
    found = Search()
    nodes = scorer.root()
    for _ in range(scorer.horizon):
        if deadline.expired() and nodes.level > 0 and width > 1:
            found.complete = False
            width = 1  # out of time: finish the best prefix greedily
            nodes = nodes.take(ranking(scorer, nodes)[:1])
        kids = scorer.expand_all(nodes, actions, posterior=nodes.level + 1 < scorer.horizon)
        found.nodes += kids.size
        if kids.level < scorer.horizon and kids.size > width:
            kids = kids.take(np.sort(ranking(scorer, kids)[:width]))
            found.pruned = True
        nodes = kids
    found.best = best_of(scorer, nodes, None)
    return found


def answer(scorer: Scorer, found: Search, backend: str, deadline: Deadline, *,
           exact: bool, note: str) -> Result[RadioPlan]:
    """The :class:`Result` of a search (module docstring for the infeasible case)."""
    stats = {"nodes": float(found.nodes)}
    if found.best is None:
        return Result(Status.NO_SOLUTION, None, None, deadline.elapsed(), backend, None,
                      message=f"{backend}: time limit before any complete sequence",
                      stats=stats)
    best = found.best
    plan = best.plan
    proven = exact and found.complete and not found.pruned
    stats.update(reward=best.value, min_void=plan.min_void, infeasible=float(not plan.feasible))
    if plan.feasible:
        return Result(Status.OPTIMAL if proven else Status.FEASIBLE, best.value,
                      best.value if proven else None, deadline.elapsed(), backend, plan,
                      message=f"{backend}: {note}", stats=stats)
    stats["proven_infeasible"] = float(proven)
    scope = "no sequence" if proven else "no sequence searched"
    return Result(Status.INFEASIBLE if proven else Status.NO_SOLUTION, None, None,
                  deadline.elapsed(), backend, plan,
                  message=(f"{backend}: {note}; {scope} keeps the void probability above "
                           f"{scorer.settings.p_void_min:g}; least-violating plan "
                           f"(min void {plan.min_void:.4g}, reward {best.value:.4g})"),
                  stats=stats)
