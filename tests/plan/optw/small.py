"""Small instances for the preprocessing tests: one computed by hand, and random ones whose
travel times are far from a metric (plus the shared catalogue)."""

from __future__ import annotations

import numpy as np

from searchtrack.plan.optw import OPTWInstance
from searchtrack.plan.optw.labelling_core import BIG, Core
from tests.plan.optw.catalogue import catalogue

# travel 0 → 2 direct takes 8 but 0 → 1 → 2 only 2 + 1 + 3 = 6 (no triangle inequality);
# vertex 3 closes at 3 but is 9 away
TRAVEL = [[0, 2, 8, 9], [2, 0, 3, 9], [8, 3, 0, 9], [9, 9, 9, 0]]


def hand(**changes: object) -> OPTWInstance:
    """The four-vertex instance of :data:`TRAVEL` (start = end = 0), with ``changes`` applied."""
    fields: dict[str, object] = {"travel": TRAVEL, "service": [0, 1, 1, 1],
                                 "profit": [0, 1, 1, 1], "open": [0, 0, 0, 0],
                                 "close": [20, 10, 12, 3]}
    fields.update(changes)
    return OPTWInstance(**fields)  # type: ignore[arg-type]


def random_instance(seed: int) -> OPTWInstance:
    """Eight vertices with asymmetric travel far from a metric, random windows and service;
    closed, open or distinct end by ``seed % 3``."""
    rng = np.random.default_rng(seed)
    n = 8
    travel = rng.integers(1, 30, size=(n, n))
    np.fill_diagonal(travel, 0)
    opn = rng.integers(0, 40, size=n)
    close = opn + rng.integers(3, 40, size=n)
    end = [0, None, n - 1][seed % 3]
    opn[0], close[0] = 0, 80
    if end:
        opn[end], close[end] = 0, 80
    return OPTWInstance(travel=travel, service=rng.integers(0, 4, size=n),
                        profit=rng.integers(1, 9, size=n).astype(float), open=opn, close=close,
                        end=end,
                        tmax=int(rng.integers(40, 90)), name=f"random-{seed}")


def cases() -> dict[str, OPTWInstance]:
    """The catalogue and nine random non-metric instances, by name."""
    return {**catalogue(), **{f"random-{s}": random_instance(s) for s in range(9)}}


def single_vehicle_cases() -> dict[str, OPTWInstance]:
    """The catalogue's one-vehicle instances and six random non-metric ones, by name."""
    base = {k: v for k, v in catalogue().items() if k.endswith("m1")}
    return {**base, **{f"random-{s}": random_instance(s) for s in range(6)}}


def elementary_paths(core: Core) -> list[tuple[int, ...]]:
    """Every elementary feasible path ``src … snk`` of a core graph, by depth-first search over
    service starts (waiting allowed)."""
    out: list[tuple[int, ...]] = []

    def grow(path: tuple[int, ...], t: int) -> None:
        v = path[-1]
        for w in range(1, core.n):
            if w in path or core.dur[v, w] >= BIG:
                continue
            a = max(int(core.opn[w]), t + int(core.dur[v, w]))
            if a > core.cls[w]:
                continue
            if w == core.snk:
                out.append((*path, w))
            else:
                grow((*path, w), a)

    grow((core.src,), int(core.opn[core.src]))
    return out
