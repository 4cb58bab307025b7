"""Branch-and-price pricing: exact on reduced profits (negative ones too), by enumeration."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.typing import NDArray

from searchtrack.core.deadline import Deadline
from searchtrack.plan.optw import validate
from searchtrack.plan.optw.bp_master import Restrictions
from searchtrack.plan.optw.bp_pricing import Pricer, droppable
from searchtrack.plan.optw.labelling import warm_up
from searchtrack.plan.optw.labelling_core import CAP_MAX, Core, build_cores
from tests.plan.optw.catalogue import catalogue, feasible_sets
from tests.plan.optw.small import hand, single_vehicle_cases


@pytest.fixture(scope="module", autouse=True)
def _compiled() -> None:
    """Compile (or load) the labelling kernel once, outside the tests."""
    warm_up()


def test_droppable_needs_the_triangle_inequality() -> None:
    """Euclidean travel with service times is droppable everywhere; the hand instance's
    customer 1 is the shortcut 0 → 1 → 2 that beats 0 → 2, so dropping it is not safe."""
    inst = catalogue()["euclid-m1"]
    _, _, orig = build_cores(inst)
    assert droppable(inst, orig)[1:-1].all()
    h = hand()
    _, _, orig = build_cores(h)
    flags = dict(zip(orig.tolist(), droppable(h, orig).tolist(), strict=True))
    assert flags[1] is False


MODES = ["whole", "halves", "halves-bounded"]


def _pricer(fwd: Core, drop_ok: NDArray[np.bool_], mode: str) -> Pricer:
    """Whole passes, half passes joined, or half passes bounded by the table passes."""
    return Pricer(fwd, drop_ok, bidirectional=mode != "whole",
                  half_tables=mode == "halves-bounded")


@pytest.mark.parametrize("name", sorted(single_vehicle_cases()))
@pytest.mark.parametrize("drop", [True, False])
@pytest.mark.parametrize("mode", MODES)
def test_pricing_is_exact(name: str, drop: bool, mode: str) -> None:
    """Columns are feasible routes of the claimed reduced profit above the floor, one is found
    whenever some route beats the floor, and the bound covers the best route."""
    inst = single_vehicle_cases()[name]
    fwd, _, orig = build_cores(inst)
    if fwd.n <= 2:
        return
    where = {int(v): c for c, v in enumerate(orig.tolist()) if 0 < c < fwd.n - 1}
    customers = [int(c) for c in inst.customers]
    sets = feasible_sets(inst)
    rng = np.random.default_rng(len(name))
    pricer = _pricer(fwd, droppable(inst, orig), mode)
    for trial in range(6):
        pi = np.zeros(fwd.n)
        pi[1:-1] = rng.uniform(0, 1.5, fwd.n - 2) * fwd.prof[1:-1]
        prof = fwd.prof - pi
        value = {mask: sum(float(prof[where[c]]) for b, c in enumerate(customers)
                           if mask >> b & 1 and c in where) for mask in sets}
        best = max(value.values(), default=-math.inf)
        floor = best - rng.uniform(-1, 3) if trial else -1.0
        got = pricer.price(fwd.dur, prof, floor, 1e-6, drop=drop, forbidden=frozenset(),
                           collect=10**4, cap=CAP_MAX, deadline=Deadline(30.0))
        assert got.upper is not None and got.upper >= best - 1e-9
        assert bool(got.paths) == (best > floor + 1e-6)
        for path, val in zip(got.paths, got.values, strict=True):
            route = (inst.start, *(int(orig[v]) for v in path[1:-1]),
                     *(() if inst.end is None else (inst.end,)))
            assert validate(inst, [route]).feasible
            assert val == pytest.approx(float(prof[list(path[1:-1])].sum()))
            assert val > floor
    if mode != "whole":  # whole passes start with a table pass anyway
        assert (pricer.stats.get("table_passes", 0) > 0) == (mode == "halves-bounded")


@pytest.mark.parametrize("mode", MODES)
def test_pricing_honours_forbidden_customers_and_arcs(mode: str) -> None:
    """No column visits a forbidden customer or uses a forbidden arc."""
    inst = catalogue()["euclid-m1"]
    fwd, _, orig = build_cores(inst)
    pricer = _pricer(fwd, droppable(inst, orig), mode)
    node = Restrictions(forbidden=frozenset({1}), no_arcs=frozenset({(0, 2)}),
                        arcs=frozenset({(3, 4)}))
    dur = pricer.node_dur(node)
    got = pricer.price(dur, fwd.prof.copy(), 0.0, 1e-6, drop=False, forbidden=node.forbidden,
                       collect=200, cap=CAP_MAX, deadline=Deadline(30.0))
    assert got.paths
    assert all(node.allows(p, 0, fwd.n - 1) for p in got.paths)


def test_guided_pricing_returns_exact_columns() -> None:
    """The heuristic pass (after an exact one) returns feasible columns of the stated value."""
    inst = catalogue()["euclid-start-end-m1"]
    fwd, _, orig = build_cores(inst)
    pricer = Pricer(fwd, droppable(inst, orig), guide=True)
    deadline = Deadline(30.0)
    prof = fwd.prof.copy()
    assert not pricer.guided(fwd.dur, prof, 0.0, 1e-6, forbidden=frozenset(), collect=10,
                             cap=1000, deadline=deadline).paths  # nothing to be guided by yet
    pricer.price(fwd.dur, prof, 0.0, 1e-6, drop=False, forbidden=frozenset(), collect=10**6,
                 cap=CAP_MAX, deadline=deadline)
    prof[1:-1] *= 0.8
    got = pricer.guided(fwd.dur, prof, 1.0, 1e-6, forbidden=frozenset(), collect=10, cap=10**5,
                        deadline=deadline)
    assert got.paths
    for path, val in zip(got.paths, got.values, strict=True):
        assert path[0] == 0 and path[-1] == fwd.n - 1
        assert val == pytest.approx(float(prof[list(path[1:-1])].sum()))
