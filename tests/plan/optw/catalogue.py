"""Small OPTW instances with optima known by brute force, shared by every backend's tests.

``brute_force`` enumerates every ordered subset of customers (pruning a prefix as soon as it is
late), checks each candidate route with the independent validator, and combines the feasible
customer sets into ``m`` disjoint routes. It is exponential: keep ``n ≤ 8``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np

from searchtrack.plan.optw import OPTWInstance, validate


def feasible_sets(instance: OPTWInstance) -> dict[int, float]:
    """Every set of customers a single route can serve (bit ``b`` = ``instance.customers[b]``),
    with its profit; the empty set is included only if the empty route is feasible."""
    inst = instance
    customers = [int(c) for c in inst.customers]
    tail = () if inst.end is None else (inst.end,)
    # A prefix that is late as an open route stays late however it is extended (finishing at the
    # end vertex only adds travel), so it is pruned.
    prefix_check = replace(inst, end=None)
    found: dict[int, float] = {}

    def extend(prefix: tuple[int, ...], mask: int) -> None:
        check = validate(inst, [(inst.start, *prefix, *tail)])
        if check.feasible:
            found[mask] = check.profit
        for b, c in enumerate(customers):
            if mask >> b & 1:
                continue
            longer = (*prefix, c)
            if validate(prefix_check, [(inst.start, *longer)]).feasible:
                extend(longer, mask | 1 << b)

    extend((), 0)
    return found


@functools.cache
def brute_force(instance: OPTWInstance) -> float:
    """Optimal total profit of ``instance`` for its ``vehicles`` routes; ``-inf`` if no plan exists.

    Every vehicle drives a route; an unused one takes the empty route ``(start, end)``, which is
    allowed only when it is itself feasible.
    """
    sets = feasible_sets(instance)
    layer = dict(sets)
    for _ in range(instance.vehicles - 1):
        nxt: dict[int, float] = {}
        for used, value in layer.items():
            for s, p in sets.items():
                if used & s == 0:
                    nxt[used | s] = max(nxt.get(used | s, -math.inf), value + p)
        layer = nxt
    return max(layer.values(), default=-math.inf)


def _coords_instance(
    seed: int,
    n: int,
    *,
    horizon: float,
    start: int = 0,
    end: int | None = 0,
    vehicles: int = 1,
    tmax: float | None = None,
    fractional: bool = False,
) -> OPTWInstance:
    rng = np.random.default_rng(seed)
    xy = rng.integers(0, 40, size=(n, 2)).astype(float) + rng.integers(0, 10, (n, 2)) / 10
    opn = rng.uniform(0, horizon * 0.6, n).round(1)
    close = (opn + rng.uniform(5, horizon * 0.5, n)).round(1)
    service = rng.integers(0, 8, n).astype(float)
    profit = rng.integers(1, 20, n).astype(float)
    if fractional:
        profit = profit + rng.uniform(0, 1, n).round(3)
    for d in (start, end):
        if d is not None:
            opn[d], close[d], service[d], profit[d] = 0.0, horizon, 0.0, 0.0
    return OPTWInstance.from_coordinates(
        xy, profit, service, opn, close, decimals=1, start=start, end=end, tmax=tmax,
        vehicles=vehicles, name=f"coords-{seed}",
    )


def _travel_instance(
    seed: int,
    n: int,
    *,
    horizon: float,
    start: int = 0,
    end: int | None = 0,
    vehicles: int = 1,
    windows: bool = True,
    spread: float = 20.0,
) -> OPTWInstance:
    """Asymmetric travel times in ``[1, spread]`` that break the triangle inequality."""
    rng = np.random.default_rng(seed)
    travel = rng.uniform(1, spread, (n, n)).round(2)
    np.fill_diagonal(travel, 0.0)
    profit = rng.uniform(1, 10, n).round(0)
    opn = close = service = None
    if windows:
        opn = rng.uniform(0, horizon * 0.5, n).round(2)
        close = (opn + rng.uniform(2, horizon * 0.6, n)).round(2)
        service = rng.uniform(0, 3, n).round(2)
        for d in (start, end):
            if d is not None:
                opn[d], close[d], service[d] = 0.0, horizon, 0.0
    return OPTWInstance.from_travel_times(
        travel, profit, service=service, open=opn, close=close, start=start, end=end,
        tmax=horizon, vehicles=vehicles, time_scale=100, name=f"travel-{seed}",
    )


def _detour_instance(vehicles: int) -> OPTWInstance:
    """The direct arc start → end is too slow; detours through customer 1 or 2 are fast enough."""
    travel = np.array([[0, 2, 2, 9], [9, 0, 9, 2], [9, 9, 0, 2], [9, 9, 9, 0]])
    return OPTWInstance.from_travel_times(
        travel, [0, 3, 5, 0], start=0, end=3, tmax=5, vehicles=vehicles, time_scale=1,
        name=f"detour-m{vehicles}",
    )


def _closed_instance() -> OPTWInstance:
    """Every customer's window closes before anyone can get there."""
    travel = np.full((4, 4), 10.0)
    np.fill_diagonal(travel, 0.0)
    return OPTWInstance.from_travel_times(
        travel, [0, 1, 2, 3], open=[0, 0, 0, 0], close=[100, 5, 5, 5], tmax=100, time_scale=1,
        name="closed",
    )


@functools.cache
def catalogue() -> dict[str, OPTWInstance]:
    """Name → small instance (n ≤ 8), covering every modelling corner the backends must handle."""
    cases = {
        "euclid-m1": _coords_instance(1, 8, horizon=120),
        "euclid-m2": _coords_instance(2, 8, horizon=100, vehicles=2),
        "euclid-m3": _coords_instance(3, 8, horizon=90, vehicles=3),
        "euclid-start-end-m1": _coords_instance(4, 8, horizon=120, start=0, end=7),
        "euclid-start-end-m2": _coords_instance(5, 8, horizon=90, start=2, end=5, vehicles=2),
        "euclid-open-m1": _coords_instance(6, 8, horizon=100, end=None),
        "euclid-open-m2": _coords_instance(7, 8, horizon=80, end=None, vehicles=2),
        "euclid-tmax-m1": _coords_instance(8, 8, horizon=200, tmax=70),
        "euclid-tmax-m2": _coords_instance(9, 8, horizon=200, tmax=110, vehicles=2),
        "euclid-fraction-m1": _coords_instance(10, 8, horizon=120, fractional=True),
        "euclid-fraction-m2": _coords_instance(11, 8, horizon=100, fractional=True, vehicles=2),
        "asym-m1": _travel_instance(12, 8, horizon=60),
        "asym-m2": _travel_instance(13, 8, horizon=50, vehicles=2, spread=45),
        "asym-start-end-m1": _travel_instance(14, 8, horizon=60, start=3, end=0, spread=30),
        "asym-start-end-m2": _travel_instance(
            15, 7, horizon=50, start=1, end=6, vehicles=2, spread=30
        ),
        "asym-open-m1": _travel_instance(16, 8, horizon=40, end=None),
        "asym-open-m2": _travel_instance(17, 8, horizon=35, end=None, vehicles=2),
        "asym-nowindows-m1": _travel_instance(18, 8, horizon=40, windows=False, spread=30),
        "asym-nowindows-m2": _travel_instance(
            19, 8, horizon=30, windows=False, vehicles=2, spread=30
        ),
        "detour-m1": _detour_instance(1),
        "detour-m2": _detour_instance(2),
        "detour-m3": _detour_instance(3),
        "closed": _closed_instance(),
    }
    return cases
