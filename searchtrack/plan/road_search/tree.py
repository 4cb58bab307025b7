"""The look-ahead tree of the receding-horizon controller (Moore et al. 2021, §4.2), searched
level by level over one UAV's time-expanded graph, vectorised over the paths of a level.

Each path carries its coverage vector (the best ``β`` each particle group has got so far, from
this path and from a ``base`` of elements other UAVs fly): a child's coverage is the elementwise
maximum with the cover row of the element it flies, its value the coverage times the group
values. That is the paper's "remove the particles counted on this edge" without copying particle
sets. Without a width the search is exhaustive (the paper's ``O(M N d^L)`` tree, here
``O(G d^L)`` with ``G`` particle groups), done depth-first over chunks of a level so that memory
stays bounded; with a width ``K`` it is a beam search keeping the ``K`` best paths of each level.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from searchtrack.core.deadline import Deadline
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.plan.road_search.scenario import Lattice, Scenario

#: Most floats a level's coverage matrix may hold before the exhaustive search splits it.
CHUNK_FLOATS = 1 << 21


@dataclass(frozen=True)
class PathSearch:
    """The best path a search found (``arcs is None`` when it found none in time).

    Parameters
    ----------
    arcs
        ``(L,)`` arcs of the path in the UAV's lattice.
    value
        Objective of the path together with the base.
    coverage
        ``(G,)`` coverage vector of the path together with the base.
    complete
        Every path was scored or pruned by width (the time limit cut nothing).
    pruned
        The width discarded some paths.
    """

    arcs: IntArray | None
    value: float
    coverage: FloatArray | None
    complete: bool
    pruned: bool


def path_count(lattice: Lattice) -> int:
    """Number of paths from the start to the last level (root-to-leaf paths of the tree)."""
    count = np.zeros(lattice.n_states, dtype=np.float64)
    count[0] = 1.0
    depth = int(lattice.state_level.max())
    for level in range(depth):
        arcs = np.flatnonzero(lattice.arc_level == level)
        np.add.at(count, lattice.arc_head[arcs], count[lattice.arc_tail[arcs]])
    total = float(count[lattice.state_level == depth].sum())
    return int(min(total, float(np.iinfo(np.int64).max)))


def children(scenario: Scenario, lattice: Lattice, state: IntArray,
             coverage: FloatArray) -> tuple[IntArray, IntArray, FloatArray, FloatArray]:
    """Every one-edge extension of the paths ending at ``state`` with ``coverage`` ``(F, G)``:
    ``(parent, arc, coverage, value)`` of the children, in (parent, arc) order."""
    lo = lattice.out_ptr[state]
    counts = lattice.out_ptr[state + 1] - lo
    parent = np.repeat(np.arange(state.size), counts)
    arc = lo[parent] + np.arange(parent.size) - np.repeat(np.cumsum(counts) - counts, counts)
    cov = np.maximum(coverage[parent], scenario.cover[lattice.arc_element[arc]])
    return parent, arc, cov, scenario.value_of(cov)


def search(scenario: Scenario, uav: int, base: FloatArray, deadline: Deadline, *,
           width: int | None = None) -> PathSearch:
    """The best path of UAV ``uav`` given the ``base`` coverage ``(G,)`` (other UAVs' elements).

    Exhaustive (``width=None``: the first best path in enumeration order) or a beam of
    ``width`` paths per level (ties kept in enumeration order). Stops at ``deadline`` with the
    best complete path found so far (``complete=False``).
    """
    lat = scenario.lattices[uav]
    depth = int(lat.state_level.max())
    g = max(1, scenario.n_groups)
    degree = int(np.diff(lat.out_ptr).max())
    best: list[tuple[float, IntArray, FloatArray]] = []
    flags = {"complete": True, "pruned": False}

    def visit(level: int, arcs: IntArray, state: IntArray, cov: FloatArray,
              value: FloatArray) -> None:
        if level == depth:
            i = int(np.argmax(value))
            if not best or value[i] > best[0][0]:
                best[:] = [(float(value[i]), arcs[i], cov[i])]
            return
        if deadline.expired():
            flags["complete"] = False
            return
        rows = max(1, CHUNK_FLOATS // (degree * g))
        if width is None and state.size > rows:
            for lo in range(0, state.size, rows):
                hi = lo + rows
                visit(level, arcs[lo:hi], state[lo:hi], cov[lo:hi], value[lo:hi])
            return
        parent, arc, child_cov, child_value = children(scenario, lat, state, cov)
        if width is not None and arc.size > width:
            keep = np.lexsort((np.arange(arc.size), -child_value))[:width]
            keep.sort()  # enumeration order among the kept
            parent, arc = parent[keep], arc[keep]
            child_cov, child_value = child_cov[keep], child_value[keep]
            flags["pruned"] = True
        visit(level + 1, np.column_stack([arcs[parent], arc]), lat.arc_head[arc], child_cov,
              child_value)

    start = base[None, :]
    visit(0, np.zeros((1, 0), dtype=np.int64), np.zeros(1, dtype=np.int64), start,
          scenario.value_of(start))
    if not best:
        return PathSearch(None, -np.inf, None, False, flags["pruned"])
    _, arcs, cov = best[0]
    # The value of the path found, evaluated on its own row: the same number however the levels
    # were chunked (a matrix product's rounding depends on its row count).
    value = float(scenario.value_of(cov[None, :])[0])
    return PathSearch(arcs, value, cov, flags["complete"], flags["pruned"])


def all_leaves(scenario: Scenario, uav: int, deadline: Deadline) -> tuple[IntArray, FloatArray]:
    """Every path of UAV ``uav``: ``(n, L)`` arcs and ``(n, G)`` coverage vectors (empty arrays
    if the deadline expires first). Only for small trees (the joint exhaustive search)."""
    lat = scenario.lattices[uav]
    depth = int(lat.state_level.max())
    arcs = np.zeros((1, 0), dtype=np.int64)
    state = np.zeros(1, dtype=np.int64)
    cov = np.zeros((1, scenario.n_groups))
    for _ in range(depth):
        if deadline.expired():
            return np.zeros((0, depth), dtype=np.int64), np.zeros((0, scenario.n_groups))
        parent, arc, cov, _value = children(scenario, lat, state, cov)
        arcs = np.column_stack([arcs[parent], arc])
        state = lat.arc_head[arc]
    return arcs, cov
