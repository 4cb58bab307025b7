"""Route helpers shared by the exact OPTW backends: idle plans, profits, schedules, checks."""

from __future__ import annotations

import itertools
from collections.abc import Sequence

from searchtrack.core.errors import InvalidInputError
from searchtrack.plan.optw.instance import OPTWInstance, Route, Routes


def idle_routes(instance: OPTWInstance) -> Routes:
    """``m`` unused routes: ``(start, end)``, or ``(start,)`` for an open end."""
    idle: Route = (instance.start,) if instance.end is None else (instance.start, instance.end)
    return (idle,) * instance.vehicles


def routes_profit(instance: OPTWInstance, routes: Routes) -> float:
    """Profit collected by ``routes`` (start and end excluded), in the instance's float profits."""
    end_index = None if instance.end is None else -1
    seen = {v for r in routes for v in r[1:end_index]}
    return float(sum(float(instance.profit[v]) for v in sorted(seen)))


def schedule(instance: OPTWInstance, route: Sequence[int]) -> tuple[int, ...]:
    """Service-start times (ticks) along ``route``; the last entry is the finish time.

    For a closed end the finish is the arrival at the end vertex; for an open end it is the end of
    the last service.

    Raises
    ------
    InvalidInputError
        If the route does not start (and end) where it must or breaks a window or the time limit.
    """
    inst = instance
    r = [int(v) for v in route]
    if not r or r[0] != inst.start:
        raise InvalidInputError("route", tuple(r), f"must start at vertex {inst.start}")
    inner = r[1:] if inst.end is None else r[1:-1]
    if inst.end is not None and (len(r) < 2 or r[-1] != inst.end):
        raise InvalidInputError("route", tuple(r), f"must end at vertex {inst.end}")
    customers = set(inst.customers.tolist())
    if any(v not in customers for v in inner) or len(set(inner)) != len(inner):
        raise InvalidInputError("route", tuple(r), "visits a non-customer or a customer twice")
    times = [inst.departure]
    for prev, v in itertools.pairwise(r):
        arrival = times[-1] + int(inst.service[prev]) + int(inst.travel[prev, v])
        if inst.end is not None and v == inst.end and len(times) == len(r) - 1:
            times.append(arrival)
            break
        begin = max(arrival, int(inst.open[v]))
        if begin > int(inst.close[v]):
            raise InvalidInputError(
                "route", tuple(r), f"reaches vertex {v} at {arrival}, after it closes "
                f"({int(inst.close[v])})"
            )
        times.append(begin)
    if inst.end is None:
        times.append(times[-1] + int(inst.service[r[-1]]))
    if times[-1] > inst.latest_finish:
        raise InvalidInputError(
            "route", tuple(r), f"finishes at {times[-1]}, after {inst.latest_finish}"
        )
    return tuple(times)


def initial_plan(instance: OPTWInstance, initial: Sequence[Sequence[int]]) -> Routes:
    """``initial`` as exactly ``m`` routes (idle ones appended), checked.

    Raises
    ------
    InvalidInputError
        Naming ``initial``, if it has too many routes or a route is infeasible.
    """
    routes = tuple(tuple(int(v) for v in r) for r in initial)
    if len(routes) > instance.vehicles:
        raise InvalidInputError("initial", routes, f"has more than {instance.vehicles} routes")
    routes += idle_routes(instance)[len(routes):]
    check_plan(instance, routes, "initial")
    return routes


def check_plan(instance: OPTWInstance, routes: Routes, name: str) -> None:
    if len(routes) != instance.vehicles:
        raise InvalidInputError(name, routes, f"needs exactly {instance.vehicles} routes")
    end_index = None if instance.end is None else -1
    inner = [v for r in routes for v in r[1:end_index]]
    if len(set(inner)) != len(inner):
        raise InvalidInputError(name, routes, "visits a customer on two routes")
    for r in routes:
        try:
            schedule(instance, r)
        except InvalidInputError as exc:
            raise InvalidInputError(name, routes, f"route {tuple(r)}: {exc.reason}") from None
