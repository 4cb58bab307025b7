"""Compiling branch-and-price's kernels ahead of a solve: the bidirectional pricing (its half
passes and their join, with and without subset-row cuts), route enumeration and reduced-cost arc
fixing, each called once on a small instance's root graph (a whole solve of a small instance
closes its root before enumeration or fixing would run, and costs the LP and CP-SAT besides)."""

from __future__ import annotations

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw.bp_cuts import SubsetRowCut, masks
from searchtrack.plan.optw.bp_enumeration import enumerate_routes
from searchtrack.plan.optw.bp_fixing import fixable_arcs
from searchtrack.plan.optw.bp_pricing import Pricer, droppable
from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.plan.optw.labelling_core import CAP_MAX, build_cores
from searchtrack.plan.optw.labelling_kernels import DONE

__all__ = ["small_instance", "warm_up"]


def small_instance() -> OPTWInstance:
    """Twelve customers with wide windows around a central depot, two vehicles."""
    rng = np.random.default_rng(0)
    xy = rng.uniform(0.0, 20.0, (13, 2))
    opn = rng.uniform(0.0, 30.0, 13).round(1)
    close = (opn + rng.uniform(20.0, 70.0, 13)).round(1)
    service, profit = rng.integers(1, 5, 13).astype(float), rng.integers(1, 10, 13).astype(float)
    xy[0], opn[0], close[0], service[0], profit[0] = 10.0, 0.0, 100.0, 0.0, 0.0
    return OPTWInstance.from_coordinates(xy, profit, service, opn, close, decimals=1,
                                         tmax=60.0, vehicles=2)


def warm_up() -> None:
    """Compile (or load from numba's cache) the kernels of branch-and-price: on
    :func:`small_instance`'s root graph, price bidirectionally with and without a subset-row
    cut, enumerate the routes with and without it and find the fixable arcs."""
    inst = small_instance()
    fwd, _, orig = build_cores(inst)
    pricer = Pricer(fwd, droppable(inst, orig), bidirectional=True)
    deadline = Deadline(60.0)
    cut = SubsetRowCut(frozenset({1, 2, 3}), frozenset({1, 2, 3, 4}))
    for priced_cuts in ((), (cut,)):
        pricer.price(fwd.dur, fwd.prof, 0.0, 0.0, drop=False, forbidden=frozenset(),
                     collect=10, cap=CAP_MAX, deadline=deadline, cuts=priced_cuts,
                     sigma=np.ones(len(priced_cuts)))
    # the passes behind enumeration's completion table and arc fixing, run once for both
    core, rev, idx, ng = pricer.graphs(fwd.dur, fwd.prof, frozenset())
    ahead, back = (pricer.bound_pass(g, ng, 0.0, CAP_MAX, deadline) for g in (core, rev))
    if back.code == DONE:
        for cuts in (None, masks([cut], np.ones(1), idx)):
            enumerate_routes(core, back.table(), 0.0, labels=1 << 20, routes=1 << 20,
                             deadline=deadline, cuts=cuts)
    fixable_arcs(core, ahead, back, 0.0)
