"""Reduced-cost arc fixing: no fixed arc carries a route of value θ or more (against every
elementary path, with random duals), the customers it leaves droppable, and branch-and-price
with fixing at the brute-force optimum."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw.bp import Tuning
from searchtrack.plan.optw.bp_fixing import fixable_arcs, leave_out
from searchtrack.plan.optw.bp_master import Restrictions
from searchtrack.plan.optw.bp_pricing import Pricer, droppable
from searchtrack.plan.optw.labelling import warm_up
from searchtrack.plan.optw.labelling_core import BIG, CAP_MAX, build_cores
from tests.plan.optw.small import elementary_paths, random_instance
from tests.plan.optw.test_bp import branching_optima, grid_instance


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    warm_up()


def test_no_fixed_arc_carries_a_good_route() -> None:
    """Random reduced profits and thresholds: every arc a route of value at least θ uses is
    kept, and at the higher thresholds some arcs are fixed."""
    fixed = 0
    for seed in range(16):
        inst = random_instance(seed) if seed % 2 else grid_instance(seed, 9, 2)
        fwd, _, orig = build_cores(inst)
        rng = np.random.default_rng(200 + seed)
        prof = np.zeros(fwd.n)
        prof[1:-1] = fwd.prof[1:-1] * (1.0 - rng.uniform(0.0, 1.2, fwd.n - 2))
        pricer = Pricer(fwd, droppable(inst, orig))
        core, rev, _, ng = pricer.graphs(pricer.node_dur(Restrictions()), prof,
                                         frozenset())
        paths = elementary_paths(core)
        value = {p: float(core.prof[list(p[1:-1])].sum()) for p in paths}
        for quantile in (0.0, 0.5, 0.9, 1.0):
            theta = float(np.quantile(list(value.values()), quantile)) - 1e-7
            ahead, back = (pricer.bound_pass(g, ng, theta, CAP_MAX, Deadline(30))
                           for g in (core, rev))
            arcs = fixable_arcs(core, ahead, back, theta)
            assert arcs is not None
            used = {a for p in paths if value[p] >= theta for a in itertools.pairwise(p)}
            assert not any(arcs[a] for a in used), (seed, quantile)
            assert not arcs[core.dur >= BIG].any()  # only arcs are fixed
            fixed += int(arcs.sum())
    assert fixed > 50


def test_a_customer_stays_droppable_only_with_its_shortcuts() -> None:
    """Fixing the shortcut ``i → k`` around a droppable customer ``j`` makes ``j`` stay in the
    pricing graph; fixing an arc no shortcut needs leaves the others droppable."""
    inst = grid_instance(4, 9, 2)
    fwd, _, orig = build_cores(inst)
    drop = droppable(inst, orig)
    j = int(np.flatnonzero(drop)[0])
    arc = fwd.dur < BIG
    into, out = np.flatnonzero(arc[:, j]), np.flatnonzero(arc[j, :])
    pairs = [(int(i), int(k)) for i in into for k in out
             if i != k and not (i == fwd.src and k == fwd.snk)]
    assert pairs
    pricer = Pricer(fwd, drop.copy())
    cut = np.zeros_like(arc)
    cut[pairs[0]] = True
    leave_out(pricer, cut)
    assert not pricer.drop_ok[j]
    assert pricer.node_dur(Restrictions())[pairs[0]] == BIG
    assert pricer.drop_ok.sum() < drop.sum()


def test_branch_and_price_with_fixed_arcs_at_the_optimum() -> None:
    """Twelve customers, two and three vehicles, no cuts and no enumeration (so the trees
    branch on the fixed graphs): every answer is the brute-force optimum, and arcs were
    fixed."""
    tuning = Tuning(ils_max_s=0.02, primal_s=0.0, ils_again_max_s=0.0, cuts_per_round=0,
                    enum_labels=0, fix_arcs=True)
    fixed = sum(res.stats.get("fixed_arcs", 0.0) for res in branching_optima(tuning))
    assert fixed > 0
