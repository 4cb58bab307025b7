"""Route enumeration: every customer set within the threshold (against depth-first enumeration
of every elementary path, with random duals, cuts and node decisions), the budgets, and
branch-and-price settling nodes by it at the brute-force optimum."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Status
from searchtrack.plan.optw.bp import Tuning, solve_bp
from searchtrack.plan.optw.bp_cuts import SubsetRowCut, masks
from searchtrack.plan.optw.bp_enumeration import enumerate_routes, threshold
from searchtrack.plan.optw.bp_master import Restrictions
from searchtrack.plan.optw.bp_pricing import Pricer, droppable
from searchtrack.plan.optw.instance import OPTWInstance
from searchtrack.plan.optw.labelling import warm_up
from searchtrack.plan.optw.labelling_core import CAP_MAX, build_cores
from tests.plan.optw.small import elementary_paths, random_instance
from tests.plan.optw.test_bp import branching_optima, fast_brute, grid_instance

QUIET = Tuning(ils_max_s=0.02, primal_s=0.0, ils_again_max_s=0.0)


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    warm_up()


def _case(seed: int) -> tuple[OPTWInstance, Restrictions]:
    """A small instance (non-metric or Euclidean) and node decisions for it (none, a forbidden
    customer, a removed arc, a forced arc) by ``seed``."""
    inst = random_instance(seed) if seed % 2 else grid_instance(seed, 9, 2)
    fwd = build_cores(inst)[0]
    rng = np.random.default_rng(seed)
    inner = [(int(i), int(j)) for i, j in zip(*np.nonzero(fwd.dur[1:-1, 1:-1] < 1 << 40),
                                             strict=True) if i != j]
    kind = seed % 4
    if kind == 1 and fwd.n > 3:
        return inst, Restrictions(forbidden=frozenset({int(rng.integers(1, fwd.n - 1))}))
    if kind >= 2 and inner:
        i, j = inner[int(rng.integers(len(inner)))]
        arc = (i + 1, j + 1)
        return inst, Restrictions(no_arcs=frozenset({arc}) if kind == 2 else frozenset(),
                                  arcs=frozenset({arc}) if kind == 3 else frozenset())
    return inst, Restrictions()


@pytest.mark.parametrize("with_cuts", [False, True])
def test_every_set_within_the_threshold_is_listed(with_cuts: bool) -> None:
    """Random duals, random limited-memory cuts and node decisions: the listed customer sets
    are exactly those some elementary path of the node (found by depth-first search) serves
    with a value of at least θ, one path each, and each listed path is that good."""
    checked = 0
    for seed in range(16):
        inst, restr = _case(seed)
        fwd, _, orig = build_cores(inst)
        if fwd.n < 4:
            continue
        rng = np.random.default_rng(100 + seed)
        pi = np.zeros(fwd.n)
        pi[1:-1] = rng.uniform(0.0, 1.2, fwd.n - 2) * fwd.prof[1:-1]
        cuts: list[SubsetRowCut] = []
        sigma = np.zeros(0)
        if with_cuts and fwd.n >= 5:
            for _ in range(3):
                sub = frozenset(int(v) for v in rng.choice(np.arange(1, fwd.n - 1), 3,
                                                           replace=False))
                extra = {int(v) for v in np.arange(1, fwd.n - 1) if rng.random() < 0.5}
                cuts.append(SubsetRowCut(sub, sub | extra))
            sigma = rng.uniform(0.0, 3.0, len(cuts))
        pricer = Pricer(fwd, droppable(inst, orig))
        dur = pricer.node_dur(restr)
        prof = np.zeros(fwd.n)
        prof[1:-1] = fwd.prof[1:-1] - pi[1:-1]
        core, idx, _ = pricer.completion_table(dur, prof, -math.inf, forbidden=restr.forbidden,
                                               cap=CAP_MAX, deadline=Deadline(30))

        paths = [tuple(int(idx[v]) for v in p) for p in elementary_paths(core)]
        value = {p: float(sum(prof[v] for v in p[1:-1]))
                 - sum(s * c.coefficient(p) for s, c in zip(sigma, cuts, strict=True))
                 for p in paths}
        best: dict[frozenset[int], float] = {}
        for p in paths:
            key = frozenset(p[1:-1])
            best[key] = max(best.get(key, -math.inf), value[p])
        for quantile in (0.0, 0.5, 0.9):
            # just below a set's value: sums in another order may differ in the last bit
            theta = float(np.quantile(list(best.values()), quantile)) - 1e-7
            _, _, table = pricer.completion_table(dur, prof, theta, forbidden=restr.forbidden,
                                                  cap=CAP_MAX, deadline=Deadline(30))
            assert table is not None
            got = enumerate_routes(core, table, theta, labels=1 << 20, routes=1 << 20,
                                   deadline=Deadline(30), cuts=masks(cuts, sigma, idx))
            assert got is not None
            listed = [tuple(int(idx[v]) for v in p) for p in got.paths]
            sets = [frozenset(p[1:-1]) for p in listed]
            assert len(sets) == len(set(sets))  # one path per set
            assert set(sets) == {k for k, v in best.items() if v >= theta}, (seed, quantile)
            assert all(p in value and value[p] >= theta - 1e-9 for p in listed)
            checked += 1
    assert checked >= 30


def test_budgets_give_up() -> None:
    """Past the label or the route budget (or the deadline) the enumeration answers None."""
    inst = grid_instance(3, 13, 2)
    fwd, _, orig = build_cores(inst)
    pricer = Pricer(fwd, droppable(inst, orig))
    core, _, table = pricer.completion_table(fwd.dur, fwd.prof, -math.inf,
                                             forbidden=frozenset(), cap=CAP_MAX,
                                             deadline=Deadline(30))
    assert table is not None
    whole = enumerate_routes(core, table, -math.inf, labels=1 << 22, routes=1 << 22,
                             deadline=Deadline(30))
    assert whole is not None and len(whole.paths) > 10
    assert enumerate_routes(core, table, -math.inf, labels=whole.labels - 1, routes=1 << 22,
                            deadline=Deadline(30)) is None
    assert enumerate_routes(core, table, -math.inf, labels=1 << 22,
                            routes=len(whole.paths) - 1, deadline=Deadline(30)) is None
    assert enumerate_routes(core, table, -math.inf, labels=1 << 22, routes=1 << 22,
                            deadline=Deadline(1e-9)) is None


def test_threshold() -> None:
    """θ = U − (L − z* − s): a route ``L − z* − s`` below the best still counts."""
    assert threshold(10.0, 100.0, 95.0, 1.0) == pytest.approx(6.0, abs=1e-5)
    assert threshold(10.0, 100.0, 95.0, 1.0) < 6.0  # a tolerance below, never above
    assert threshold(10.0, 100.0, 95.0, 0.0) < 5.0


def test_branch_and_price_settles_nodes_at_the_optimum() -> None:
    """Twelve customers, wide windows, two and three vehicles, no cuts (so more roots stay
    fractional): with enumeration every answer is the brute-force optimum, proven, and
    enumeration settled some of the nodes."""
    tuning = Tuning(ils_max_s=0.02, primal_s=0.0, ils_again_max_s=0.0, cuts_per_round=0)
    settled = 0.0
    for res in branching_optima(tuning):
        settled += res.stats.get("enum_settled", 0.0)
        said = "settled by route enumeration" in res.message
        assert said == bool(res.stats.get("enum_settled", 0.0)), res.message
    assert settled >= 3


def test_with_cuts_and_a_small_budget_still_optimal() -> None:
    """With cuts in the labels, and with a budget so small that most tries fail (the tree goes
    on branching): the same optima."""
    for seed in range(6):
        inst = grid_instance(seed, 13, 2 + seed % 2)
        for labels in (50, 1 << 22):
            res = solve_bp(inst, time_limit_s=20,
                           tuning=Tuning(ils_max_s=0.02, primal_s=0.0, ils_again_max_s=0.0,
                                         enum_labels=labels))
            assert res.status is Status.OPTIMAL
            assert res.objective == pytest.approx(fast_brute(inst))
