"""The shared labelling core: core graphs and their reversal, ng-sets, cycle forbidding, and
one pass (exact with full memory, the same in both directions, collect mode)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw import validate
from searchtrack.plan.optw.labelling import warm_up
from searchtrack.plan.optw.labelling_core import (
    BIG,
    CAP_MAX,
    Core,
    CutMasks,
    PassResult,
    base_ng,
    build_cores,
    core_pair,
    forbid_cycles,
    initial_ng,
    instance_route,
    run_pass,
)
from searchtrack.plan.optw.labelling_kernels import DONE, ENOUGH
from tests.plan.optw.catalogue import brute_force
from tests.plan.optw.small import hand, random_instance, single_vehicle_cases


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the labelling kernel once, outside the tests."""
    warm_up()


def _bits(ng: np.ndarray, row: int) -> set[int]:
    """The vertices whose bits are set in ``ng[row]``."""
    return {64 * w + b for w in range(ng.shape[1]) for b in range(64)
            if int(ng[row, w]) >> b & 1}


def _arcs(core: Core, v: int) -> list[int]:
    return core.succ[core.succ_ptr[v]:core.succ_ptr[v + 1]].tolist()


def test_build_cores_keeps_reachable_customers_and_reverses_time() -> None:
    """On the hand instance customer 3 (closing before anyone can reach it) is left out; the
    reversal swaps source and sink, transposes the arcs and mirrors the windows at ``H``."""
    fwd, rev, orig = build_cores(hand())
    assert orig.tolist() == [0, 1, 2, 0]
    assert (fwd.src, fwd.snk, rev.src, rev.snk) == (0, 3, 3, 0)
    assert np.array_equal(rev.dur, fwd.dur.T) and np.array_equal(rev.sp, fwd.sp.T)
    h = fwd.horizon
    assert rev.horizon == h
    assert np.array_equal(rev.opn, h - fwd.cls) and np.array_equal(rev.cls, h - fwd.opn)
    assert fwd.dur[0, 2] == 8 and fwd.sp[0, 2] == 6  # 0 → 1 → 2 beats the direct arc
    for core in (fwd, rev):
        for v in range(core.n):
            succ = _arcs(core, v)
            assert sorted(succ) == np.flatnonzero(core.dur[v] < BIG).tolist()
            assert core.dur[v, succ].tolist() == sorted(core.dur[v, succ].tolist())


def test_core_pair_matches_build_cores() -> None:
    """The pair built from a core's own durations and windows is that core and its reversal."""
    for inst in single_vehicle_cases().values():
        fwd, rev, _ = build_cores(inst)
        f2, r2 = core_pair(fwd.dur, fwd.opn, fwd.cls, fwd.prof, fwd.src, fwd.snk, fwd.horizon)
        for a, b in ((fwd, f2), (rev, r2)):
            for name in ("dur", "sp", "succ_ptr", "succ", "opn", "cls", "prof", "thr", "cum"):
                assert np.array_equal(getattr(a, name), getattr(b, name)), name
            assert (a.src, a.snk, a.horizon) == (b.src, b.snk, b.horizon)


def test_instance_route_adds_start_and_end() -> None:
    """Core vertices map back through ``orig``; an open end adds no end vertex."""
    closed = hand()
    _, _, orig = build_cores(closed)
    assert instance_route(closed, orig, [0, 2, 1, 3]) == (0, 2, 1, 0)
    assert instance_route(closed, orig, [0, 3]) == (0, 0)
    open_end = hand(end=None)
    _, _, orig = build_cores(open_end)
    assert instance_route(open_end, orig, [0, 1, int(orig.size) - 1]) == (0, 1)


def test_ng_sets_remember_the_vertex_itself_and_its_nearest() -> None:
    """Every customer remembers itself; ``initial_ng`` adds at most ``size`` others, source and
    sink remember nothing; size 0 leaves the vertex alone."""
    fwd, _, _ = build_cores(random_instance(4))
    base = base_ng(fwd)
    for size in (0, 2, fwd.n):
        ng = initial_ng(fwd, size)
        assert not _bits(ng, fwd.src) and not _bits(ng, fwd.snk)
        for v in range(1, fwd.n - 1):
            assert v in _bits(ng, v) and v in _bits(base, v)
            assert len(_bits(ng, v)) <= size + 1
            assert _bits(ng, v) <= set(range(1, fwd.n - 1))
        if size == 0:
            assert all(_bits(ng, v) == {v} for v in range(1, fwd.n - 1))


def test_forbid_cycles_adds_each_missing_bit_once() -> None:
    """The cycle 1 → 2 → 3 → 1 makes 2 and 3 remember 1; a second call adds nothing."""
    ng = np.zeros((6, 1), dtype=np.uint64)
    pairs: list[tuple[int, int]] = []
    assert forbid_cycles(ng, [0, 1, 2, 3, 1, 5], pairs) == 2
    assert pairs == [(2, 1), (3, 1)]
    assert _bits(ng, 2) == {1} and _bits(ng, 3) == {1} and not _bits(ng, 1)
    assert forbid_cycles(ng, [0, 1, 2, 3, 1, 5]) == 0
    assert forbid_cycles(ng, [0, 1, 2, 5]) == 0


@pytest.mark.parametrize("name", sorted(single_vehicle_cases()))
def test_a_pass_with_full_memory_is_exact_both_ways(name: str) -> None:
    """With every visit remembered a pass finds the optimum, forward and backward alike; its
    best label is a feasible route of that profit, and its profit table is non-decreasing in
    time and holds the profit of each label on that route."""
    inst = single_vehicle_cases()[name]
    fwd, rev, orig = build_cores(inst)
    if fwd.n <= 2:
        return
    best = brute_force(inst)
    ng = base_ng(fwd) | initial_ng(fwd, fwd.n)
    gap = 1e-6
    for direction, core in enumerate((fwd, rev)):
        out = run_pass(core, ng, None, lb=-math.inf, gap=gap, cap=CAP_MAX,
                       deadline=Deadline(30.0))
        assert out.code == DONE and out.sinks.size == 0 and out.labels >= 1
        if best == -math.inf:
            assert out.best < 0
            continue
        assert out.lb == pytest.approx(best)
        path = out.path(out.best)
        route = instance_route(inst, orig, path if direction == 0 else path[::-1])
        check = validate(inst, [route])
        assert check.feasible and check.profit == pytest.approx(best)
        table = out.table()
        assert np.array_equal(table, np.fmax.accumulate(table, axis=1))
        x = int(out.par[out.best])
        while x > 0:  # each customer label of the best path is in the table
            assert table[out.lv[x], -1] >= out.lp[x]
            x = int(out.par[x])


def test_collect_mode_keeps_the_floor_and_stops_when_enough() -> None:
    """In collect mode every path found beats the fixed floor and is elementary; asking for one
    path stops the pass with ``ENOUGH`` as soon as it is found."""
    inst = random_instance(2)
    fwd, _, _ = build_cores(inst)
    ng = base_ng(fwd) | initial_ng(fwd, fwd.n)
    floor = 0.5 * brute_force(inst)
    out = run_pass(fwd, ng, None, lb=floor, gap=1e-6, cap=CAP_MAX, deadline=Deadline(30.0),
                   collect=1000)
    assert out.code == DONE and out.found.size > 1 and out.lb == floor
    for s in out.found.tolist():
        path = out.path(s)
        assert out.lp[s] > floor and len(set(path)) == len(path)
        assert out.lp[s] == pytest.approx(float(fwd.prof[path].sum()))
    one = run_pass(fwd, ng, None, lb=floor, gap=1e-6, cap=CAP_MAX, deadline=Deadline(30.0),
                   collect=1)
    assert one.code == ENOUGH and one.found.size == 1


def _random_cuts(n: int, rng: np.random.Generator) -> CutMasks:
    """Three subset-row cuts on random triples of customers, with random memories and duals."""
    subset = np.zeros((n, 1), dtype=np.uint64)
    memory = np.zeros((n, 1), dtype=np.uint64)
    for c in range(3):
        bit = np.uint64(1) << np.uint64(c)
        members = rng.choice(np.arange(1, n - 1), size=min(3, n - 2), replace=False)
        subset[members, 0] |= bit
        memory[members, 0] |= bit
        memory[rng.random(n) < 0.5, 0] |= bit
    dual = np.zeros(64)
    dual[:3] = rng.uniform(0.0, 5.0, size=3)
    return CutMasks(subset, memory, dual)


@pytest.mark.parametrize("seed", range(8))
def test_a_pass_does_not_depend_on_the_room_it_starts_with(seed: int) -> None:
    """Starting from a store of one label (every array then grows while the pass runs) gives
    the very pass a roomy store gives: the same labels, paths and stop code, with and
    without subset-row cuts, searching or collecting."""
    inst = random_instance(seed)
    fwd, rev, _ = build_cores(inst)
    if fwd.n <= 3:
        return
    rng = np.random.default_rng(seed)
    ng = base_ng(fwd) | initial_ng(fwd, 3)
    for core, cuts, collect in ((fwd, None, 0), (rev, _random_cuts(rev.n, rng), 0),
                                (fwd, _random_cuts(fwd.n, rng), 1000)):
        runs = [run_pass(core, ng, None, lb=-math.inf if collect == 0 else 0.0, gap=1e-6,
                         cap=CAP_MAX, deadline=Deadline(30.0), collect=collect, cuts=cuts,
                         room=room) for room in (1, 3, 1 << 15)]
        first = runs[-1]
        assert first.labels > 1
        for out in runs[:-1]:
            # (the dominance work may differ: a candidate met when an array is full is checked
            # again once it has grown)
            assert (out.code, out.lb, out.best, out.labels, out.pops) == \
                (first.code, first.lb, first.best, first.labels, first.pops)
            assert np.array_equal(out.sinks, first.sinks)
            assert np.array_equal(out.found, first.found)
            k = first.labels
            for a, b in ((out.lv, first.lv), (out.lp, first.lp), (out.par, first.par),
                         (out.lt, first.lt), (out.alive, first.alive)):
                assert np.array_equal(a[:k], b[:k])


def _covers(out: PassResult, core: Core, x: int, y: int, sig: np.ndarray) -> bool:
    """Label ``x`` dominates label ``y`` (same vertex): no later, its mask within ``y``'s, and
    its profit enough to pay the cuts it may still owe and ``y`` not."""
    def mask(z: int) -> np.ndarray:
        v, t = int(out.lv[z]), int(out.lt[z])
        return out.lmem[z] | core.cum[v, int(np.searchsorted(core.thr[v], t, side="left"))]

    if out.lt[x] > out.lt[y] or np.any(mask(x) & ~mask(y)):
        return False
    owed = sum(float(sig[c]) for w in range(out.lc.shape[1]) for c in range(64)
               if int(out.lc[x, w] & ~out.lc[y, w]) >> c & 1)
    return bool(out.lp[x] - owed >= out.lp[y])


@pytest.mark.parametrize("seed", range(6))
def test_live_labels_are_an_antichain_and_every_dead_label_is_covered(seed: int) -> None:
    """Dominance is complete: after a pass no two live labels at a vertex dominate one another,
    and each label marked dead is dominated by a live one (brute force over all pairs, with
    and without cuts)."""
    inst = random_instance(seed)
    fwd, _, _ = build_cores(inst)
    if fwd.n <= 3:
        return
    rng = np.random.default_rng(seed)
    ng = base_ng(fwd) | initial_ng(fwd, 2)
    for cuts in (None, _random_cuts(fwd.n, rng)):
        out = run_pass(fwd, ng, None, lb=-math.inf, gap=1e-6, cap=CAP_MAX,
                       deadline=Deadline(30.0), cuts=cuts)
        sig = np.zeros(64) if cuts is None else cuts.dual
        stored = [x for x in range(1, out.labels) if out.lv[x] != fwd.snk]
        live = [x for x in stored if out.alive[x]]
        assert len(stored) > len(live) > 0
        for x in live:
            assert not any(_covers(out, fwd, y, x, sig) for y in live
                           if y != x and out.lv[y] == out.lv[x])
        for x in stored:
            if not out.alive[x]:
                assert any(_covers(out, fwd, y, x, sig) for y in live if out.lv[y] == out.lv[x])
