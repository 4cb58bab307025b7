"""Independent check of OPTW routes: recomputes every schedule and the profit from the instance.

Shares no code with any solver: a plan a backend returns is accepted only if this module agrees.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass

from searchtrack.plan.optw.instance import OPTWInstance


@dataclass(frozen=True)
class Visit:
    """One stop of a route, times in ticks: arrival, wait before the window opens, service start."""

    vertex: int
    arrival: int
    wait: int
    start: int


@dataclass(frozen=True)
class Validation:
    """Outcome of :func:`validate`: the recomputed profit, schedules and every violation found."""

    profit: float
    schedules: tuple[tuple[Visit, ...], ...]
    violations: tuple[str, ...]

    @property
    def feasible(self) -> bool:
        """True when no constraint is violated."""
        return not self.violations


def validate(instance: OPTWInstance, routes: Sequence[Sequence[int]]) -> Validation:
    """Recompute arrival, wait and start times along ``routes`` and report every violation.

    A route is a sequence of vertex indices from ``instance.start`` to ``instance.end`` (or to its
    last visit when the end is open). An empty list of routes, or the route ``(start, end)``,
    collects nothing and is feasible when the end can be reached in time.
    """
    inst = instance
    problems: list[str] = []
    schedules: list[tuple[Visit, ...]] = []
    owner: dict[int, int] = {}
    if len(routes) > inst.vehicles:
        problems.append(f"{len(routes)} routes for {inst.vehicles} vehicles")
    finish_limit = inst.latest_finish
    for r, route in enumerate(routes):
        route = [int(v) for v in route]
        tag = f"route {r}"
        if not route:
            problems.append(f"{tag}: empty (must at least start at vertex {inst.start})")
            schedules.append(())
            continue
        if any(not 0 <= v < inst.n for v in route):
            problems.append(f"{tag}: vertex index out of range [0, {inst.n})")
            schedules.append(())
            continue
        if route[0] != inst.start:
            problems.append(f"{tag}: starts at {route[0]}, not at start vertex {inst.start}")
        if inst.end is not None:
            if len(route) < 2 or route[-1] != inst.end:
                problems.append(f"{tag}: does not end at end vertex {inst.end}")
            inner = route[1:-1]
        else:
            inner = route[1:]
        for pos, v in enumerate(inner, start=1):
            if v == inst.start or v == inst.end:
                problems.append(f"{tag}: position {pos} revisits start/end vertex {v}")
            elif v in owner:
                problems.append(f"{tag}: vertex {v} already visited by route {owner[v]}")
            else:
                owner[v] = r
        t = int(inst.open[route[0]])
        visits = [Visit(route[0], t, 0, t)]
        for prev, v in itertools.pairwise(route):
            arrival = visits[-1].start + int(inst.service[prev]) + int(inst.travel[prev, v])
            begin = max(arrival, int(inst.open[v]))
            visits.append(Visit(v, arrival, begin - arrival, begin))
            if begin > int(inst.close[v]):
                problems.append(
                    f"{tag}: arrives at vertex {v} at {arrival}, after its window closes "
                    f"({int(inst.close[v])})"
                )
        last = visits[-1]
        finish = last.arrival
        if inst.end is None:
            finish = last.start + int(inst.service[last.vertex])
        if finish > finish_limit:
            problems.append(f"{tag}: finishes at {finish}, after the limit {finish_limit}")
        schedules.append(tuple(visits))
    profit = float(sum(float(inst.profit[v]) for v in owner))
    return Validation(profit, tuple(schedules), tuple(problems))
