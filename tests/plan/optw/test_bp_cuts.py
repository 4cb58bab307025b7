"""Subset-row cuts: coefficients by their definition, separation, pricing with cut duals checked
against every route, and branch-and-price with cuts at every node against brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.core.result import Status
from searchtrack.plan.optw import OPTWInstance, bp_pricing, validate
from searchtrack.plan.optw.bp import Tuning, solve_bp
from searchtrack.plan.optw.bp_cuts import SubsetRowCut, masks, outside_memory, separate
from searchtrack.plan.optw.bp_pricing import Pricer, droppable
from searchtrack.plan.optw.labelling import warm_up
from searchtrack.plan.optw.labelling_core import CAP_MAX, build_cores
from tests.plan.optw.catalogue import brute_force, catalogue
from tests.plan.optw.small import elementary_paths, random_instance, single_vehicle_cases
from tests.plan.optw.test_bp import fast_brute, grid_instance

EVERYWHERE = Tuning(ils_max_s=0.02, primal_s=0.2, cuts_per_round=30, cuts_max=400,
                    cut_rounds=50, cut_depth=1000, enum_labels=0)


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the kernels once, outside the tests."""
    from searchtrack.plan.optw import ils

    warm_up()
    ils.warm_up()


def _alpha(cut: SubsetRowCut, path: tuple[int, ...]) -> int:
    """The limited-memory coefficient from its definition: the consecutive pairs of subset visits
    with no vertex outside the memory between them, counted left to right, a pair's second visit
    not reused."""
    at = [k for k, v in enumerate(path[1:-1]) if v in cut.subset]
    inner = path[1:-1]
    count, k = 0, 0
    while k + 1 < len(at):
        a, b = at[k], at[k + 1]
        if all(v in cut.memory for v in inner[a:b + 1]):
            count += 1
            k += 2
        else:
            k += 1
    return count


def test_coefficient_follows_the_memory() -> None:
    """Two visits joined inside the memory count, a vertex outside it between them does not."""
    cut = SubsetRowCut(frozenset({1, 2, 3}), frozenset({1, 2, 3, 4}))
    assert cut.coefficient((0, 1, 4, 2, 9)) == 1
    assert cut.coefficient((0, 1, 5, 2, 9)) == 0
    assert cut.coefficient((0, 1, 5, 2, 3, 9)) == 1
    assert cut.coefficient((0, 1, 2, 3, 9)) == 1
    assert cut.coefficient((0, 1, 7, 8, 9)) == 0
    rng = np.random.default_rng(0)
    for _ in range(500):
        s = frozenset(rng.choice(np.arange(1, 9), 3, replace=False).tolist())
        mem = s | frozenset(rng.choice(np.arange(1, 9), rng.integers(0, 6)).tolist())
        inner = rng.permutation(np.arange(1, 9))[: rng.integers(0, 9)].tolist()
        cut, path = SubsetRowCut(s, mem), (0, *inner, 9)
        assert cut.coefficient(path) == _alpha(cut, path)
        assert cut.coefficient(path) <= len(s.intersection(path)) // 2  # at most the full one


def test_separation_finds_the_half_triangle() -> None:
    """Three routes each visiting a pair of {1, 2, 3} at ½ violate the cut by ½; the memory keeps
    each route's coefficient (vertex 5 lies between two subset visits), and integral columns are
    never part of a violation."""
    paths = [(0, 1, 5, 2, 9), (0, 2, 3, 9), (0, 3, 6, 1, 9), (0, 4, 9), (0, 7, 8, 9)]
    values = np.array([0.5, 0.5, 0.5, 1.0, 0.0])
    cuts = separate(paths, values, set(), most=5)
    assert [c.subset for c in cuts] == [frozenset({1, 2, 3})]
    cut = cuts[0]
    assert {5, 6} <= cut.memory and 4 not in cut.memory
    assert sum(v * cut.coefficient(p) for p, v in zip(paths, values, strict=True)) == 1.5
    assert not separate(paths, values, {frozenset({1, 2, 3})}, most=5)
    assert not separate(paths, np.array([0.5, 0.5, 0.0, 1.0, 0.0]), set(), most=5)


def test_masks_keep_positive_duals_only() -> None:
    """Bits for the cuts of positive dual, on the pricing graph's own vertex numbers."""
    cuts = [SubsetRowCut(frozenset({1, 2, 3}), frozenset({1, 2, 3, 4})),
            SubsetRowCut(frozenset({2, 3, 4}), frozenset({2, 3, 4}))]
    assert masks(cuts, np.array([0.0, 0.0]), np.arange(6)) is None
    got = masks(cuts, np.array([0.0, 2.5]), np.array([0, 2, 3, 4, 5]))
    assert got is not None
    assert got.dual[0] == 2.5 and got.dual[1:].sum() == 0
    assert got.subset[:, 0].tolist() == [0, 1, 1, 1, 0]
    assert outside_memory(cuts, np.array([0.0, 2.5]), 6).tolist() == [
        True, True, False, False, False, True]


def _random_cuts(rng: np.random.Generator, n: int, k: int) -> list[SubsetRowCut]:
    cuts = []
    for _ in range(k):
        s = frozenset(rng.choice(np.arange(1, n - 1), 3, replace=False).tolist())
        extra = rng.choice(np.arange(1, n - 1), rng.integers(0, n - 2)).tolist()
        cuts.append(SubsetRowCut(s, s | frozenset(extra)))
    return cuts


@pytest.mark.parametrize("name", sorted(single_vehicle_cases()))
@pytest.mark.parametrize(("drop", "relaxed"), [(True, False), (False, False), (False, True)])
@pytest.mark.parametrize("bidirectional", [False, True])
def test_pricing_with_cuts_is_exact(name: str, drop: bool, relaxed: bool, bidirectional: bool,
                                    monkeypatch: pytest.MonkeyPatch) -> None:
    """With random cuts and duals, every column's value is its reduced profit less its cuts'
    duals, a column is found whenever some route beats the floor, and the bound covers the best
    route, all checked on every elementary route. ``relaxed``: one-customer ng-sets even on these
    small graphs, so that relaxed paths have cycles and the passes repeat."""
    if relaxed:
        monkeypatch.setattr(bp_pricing, "FULL_MEMORY", 0)
    inst = single_vehicle_cases()[name]
    fwd, _, orig = build_cores(inst)
    if fwd.n <= 5:
        return
    routes = elementary_paths(fwd)
    rng = np.random.default_rng(len(name) + 7 * drop + 13 * relaxed)
    pricer = Pricer(fwd, droppable(inst, orig), ng_size=1 if relaxed else 8,
                    bidirectional=bidirectional)
    for trial in range(6):
        pi = np.zeros(fwd.n)
        pi[1:-1] = rng.uniform(0, 1.2, fwd.n - 2) * fwd.prof[1:-1]
        prof = fwd.prof - pi
        cuts = _random_cuts(rng, fwd.n, int(rng.integers(1, 80)))
        sigma = np.where(rng.random(len(cuts)) < 0.7, rng.uniform(0, 3, len(cuts)), 0.0)

        def value(p: tuple[int, ...], prof: np.ndarray = prof, cuts: list[SubsetRowCut] = cuts,
                  sigma: np.ndarray = sigma) -> float:
            return float(prof[list(p[1:-1])].sum()) - sum(
                s * c.coefficient(p) for s, c in zip(sigma, cuts, strict=True))

        best = max((value(p) for p in routes), default=-math.inf)
        floor = best - rng.uniform(-1, 3) if trial else -1.0
        got = pricer.price(fwd.dur, prof, floor, 1e-6, drop=drop, forbidden=frozenset(),
                           collect=10**4, cap=CAP_MAX, deadline=Deadline(30.0), cuts=cuts,
                           sigma=sigma)
        assert got.upper is not None and got.upper >= best - 1e-9
        assert bool(got.paths) == (best > floor + 1e-6)
        for path, val in zip(got.paths, got.values, strict=True):
            route = (inst.start, *(int(orig[v]) for v in path[1:-1]),
                     *(() if inst.end is None else (inst.end,)))
            assert validate(inst, [route]).feasible
            assert val == pytest.approx(value(path))
            assert val > floor


def _solve(inst: OPTWInstance, best: float) -> float:
    res = solve_bp(inst, time_limit_s=30, tuning=EVERYWHERE)
    if best == -math.inf:
        assert res.status is Status.INFEASIBLE, res.message
        return 0.0
    assert res.status is Status.OPTIMAL, res.message
    assert res.objective == pytest.approx(best)
    assert res.plan is not None and validate(inst, res.plan).profit == pytest.approx(best)
    assert res.stats["root_bound"] >= best - 1e-6
    return res.stats.get("cuts", 0.0)


@pytest.mark.parametrize("vehicles", [2, 3])
def test_cuts_at_every_node_keep_the_optimum(vehicles: int) -> None:
    """Cuts separated at every node of the tree: still the brute-force optimum, on wide-window
    Euclidean and on non-metric instances; the wide windows do give cuts."""
    cuts = [_solve(inst, fast_brute(inst))
            for inst in (grid_instance(seed, 13, vehicles) for seed in range(10))]
    cuts += [_solve(inst, brute_force(inst))
             for inst in (random_instance(seed).with_vehicles(vehicles) for seed in range(6))]
    assert max(cuts) > 0
    for name, inst in catalogue().items():
        if not name.endswith("m1"):
            _solve(inst, brute_force(inst))
