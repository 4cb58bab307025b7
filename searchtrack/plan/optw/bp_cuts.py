"""Limited-memory subset-row cuts for the team-OPTW branch-and-price.

A subset-row cut on three customers ``S`` (Jepsen, Petersen, Spoorendonk & Pisinger 2008) says
that the routes visiting two or more of them take at most one unit in total::

    Σ_r ⌊|S ∩ r| / 2⌋ λ_r ≤ 1

It holds for every integer packing, since two routes sharing no customer cannot both visit two
of three customers, and it cuts off fractional packings where three routes each visit a
different pair with ``λ = ½``. In its limited-memory form (Pecin, Pessoa, Poggi & Uchoa 2017)
each cut carries a memory ``M ⊇ S``: a route's coefficient counts only a pair of visits of
``S`` with no vertex outside ``M`` between them. That coefficient is at most the full one, so
the cut stays valid, and pricing keeps far fewer distinct cut states. The memory of a separated
cut is ``S`` and the vertices between the two visits in each route of the fractional solution
that has the full coefficient, so the cut is as violated as its full form.

The pricing labels carry a bit per cut (:class:`searchtrack.plan.optw.labelling_core.CutMasks`);
this module holds the cuts, their coefficients, separation from a master solution, and the bit
masks of a pricing graph.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from searchtrack.plan.optw.labelling_core import CutMasks

Path = tuple[int, ...]


@dataclass(frozen=True)
class SubsetRowCut:
    """A limited-memory 3-subset-row cut on core customers (``subset ⊆ memory``)."""

    subset: frozenset[int]
    memory: frozenset[int]

    def coefficient(self, path: Path) -> int:
        """The cut's coefficient of the core route ``path`` (source … sink)."""
        hits = self.subset.intersection(path)
        if len(hits) < 2:
            return 0
        count = held = 0
        for v in path[1:-1]:
            if v not in self.memory:
                held = 0
            elif v in self.subset:
                if held:
                    count += 1
                    held = 0
                else:
                    held = 1
        return count


def separate(paths: Sequence[Path], values: NDArray[np.float64], known: set[frozenset[int]], *,
             most: int, least_violation: float = 1e-3) -> list[SubsetRowCut]:
    """The most violated 3-subset-row cuts of a master solution (at most ``most``).

    ``paths`` and ``values`` are the master's columns and their values; subsets in ``known`` are
    skipped. Every triple of customers that two or more fractional columns visit is scored by
    its full left-hand side ``Σ_r λ_r [|S ∩ r| ≥ 2]``; those above ``1 + least_violation`` are
    returned, most violated first, with the memory that keeps each violated column's coefficient.
    """
    used = [k for k in np.flatnonzero(values > 1e-6).tolist()
            if 1e-6 < values[k] < 1 - 1e-6 and len(paths[k]) > 3]
    if len(used) < 2:
        return []
    lam = values[used]
    customers = sorted({v for k in used for v in paths[k][1:-1]})
    col = {v: c for c, v in enumerate(customers)}
    a = np.zeros((len(used), len(customers)), dtype=np.float64)
    for r, k in enumerate(used):
        a[r, [col[v] for v in paths[k][1:-1]]] = 1.0
    # only customers in two or more fractional columns can be in a violated triple
    keep = np.flatnonzero((a > 0).sum(axis=0) >= 2)
    a = a[:, keep]
    names = [customers[c] for c in keep.tolist()]
    found: list[tuple[float, tuple[int, int, int]]] = []
    q = a.shape[1]
    for i in range(q - 2):
        for j in range(i + 1, q - 1):
            pair = a[:, i] + a[:, j]
            if not pair.any():
                continue
            rest = a[:, j + 1:]
            lhs = lam @ ((pair[:, None] + rest) >= 2.0)
            for k in np.flatnonzero(lhs > 1.0 + least_violation).tolist():
                s = (names[i], names[j], names[j + 1 + k])
                if frozenset(s) not in known:
                    found.append((float(lhs[k]), s))
    found.sort(key=lambda e: (-e[0], e[1]))
    return [_with_memory(frozenset(s), [paths[k] for k in used])
            for _, s in found[:most]]


def _with_memory(subset: frozenset[int], paths: Sequence[Path]) -> SubsetRowCut:
    """The cut on ``subset`` whose memory keeps each of ``paths`` at its full coefficient: the
    vertices between its first two visits of ``subset``."""
    memory = set(subset)
    for path in paths:
        at = [pos for pos, v in enumerate(path) if v in subset]
        if len(at) >= 2:
            memory.update(path[at[0] + 1:at[1]])
    return SubsetRowCut(subset, frozenset(memory))


def masks(cuts: Sequence[SubsetRowCut], duals: NDArray[np.float64],
          vertices: NDArray[np.intp]) -> CutMasks | None:
    """The bit masks of the cuts of positive dual on the pricing graph whose vertex ``u`` is
    core vertex ``vertices[u]``; ``None`` when no cut has a positive dual."""
    active = [c for c in range(len(cuts)) if duals[c] > 0.0]
    if not active:
        return None
    n = vertices.size
    words = (len(active) + 63) // 64
    subset = np.zeros((n, words), dtype=np.uint64)
    memory = np.zeros((n, words), dtype=np.uint64)
    dual = np.zeros(64 * words)
    where = {int(v): u for u, v in enumerate(vertices.tolist())}
    for bit, c in enumerate(active):
        w, b = bit >> 6, np.uint64(1) << np.uint64(bit & 63)
        dual[bit] = duals[c]
        for v in cuts[c].memory:
            if v in where:
                memory[where[v], w] |= b
        for v in cuts[c].subset:
            if v in where:
                subset[where[v], w] |= b
    return CutMasks(subset, memory, dual)


def outside_memory(cuts: Sequence[SubsetRowCut], duals: NDArray[np.float64],
                   n: int) -> NDArray[np.bool_]:
    """Core vertices outside the memory of some cut of positive dual.

    Leaving such a vertex out of a route can join two visits of that cut's subset and raise the
    route's coefficient, so pricing must not drop it on the triangle inequality alone.
    """
    out = np.zeros(n, dtype=bool)
    for c, cut in enumerate(cuts):
        if duals[c] > 0.0:
            inside = np.zeros(n, dtype=bool)
            inside[list(cut.memory)] = True
            out |= ~inside
    return out
