"""Every feasible single route of a small instance, with its schedule from the validator.

An independent reference for the preprocessing bounds (reach, arc graph, gaps): whatever they
claim about feasible routes must hold on each route listed here. Exponential: keep ``n ≤ 8``.
"""

from __future__ import annotations

import functools
from dataclasses import replace

from searchtrack.plan.optw import OPTWInstance, validate


@functools.cache
def feasible_routes(instance: OPTWInstance) -> tuple[tuple[tuple[int, ...], tuple[int, ...]], ...]:
    """``(route, service starts)`` of every feasible route, start and end included; for a closed
    end the last time is the arrival at the end, for an open end the end of the last service."""
    inst = instance
    tail = () if inst.end is None else (inst.end,)
    prefix_check = replace(inst, end=None)  # a late prefix stays late however it is extended
    found: list[tuple[tuple[int, ...], tuple[int, ...]]] = []

    def extend(prefix: tuple[int, ...]) -> None:
        route = (inst.start, *prefix, *tail)
        check = validate(inst, [route])
        if check.feasible:
            times = [visit.start for visit in check.schedules[0]]
            if inst.end is None:
                times.append(times[-1] + int(inst.service[route[-1]]))
            else:
                times[-1] = check.schedules[0][-1].arrival
            found.append((route, tuple(times)))
        for c in (int(v) for v in inst.customers):
            if c not in prefix and validate(prefix_check, [(inst.start, *prefix, c)]).feasible:
                extend((*prefix, c))

    extend(())
    return tuple(found)
