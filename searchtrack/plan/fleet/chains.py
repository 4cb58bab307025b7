"""The road map seen by a splitting mode (paper 000, §5.3): directed chains and subdivisions.

Every road is two-way, so each undirected edge gives two directed edges. A mode (a cluster of
particles) runs along a directed edge and splits only where a target has a choice, so edges through
pass-through nodes (degree 2) are merged into directed *chains* that run from a junction or dead
end to the next. Targets never U-turn except at a dead end (Assumption 3 with the simulator's
rule), so the *children* of a chain are the chains leaving its head node other than its own
reverse, or only its reverse at a dead end. A loop of pass-through nodes with no junction is cut at
its lowest-numbered node.

*Subdivisions* group chains that a mode cannot tell apart: the same length (so the same traversal
time at one target speed) and children drawn from the same subdivisions, found by colour refinement
until stable. On the 3 × 3 grid this gives the three subdivisions of the paper's Fig. 6: corner
paths (length 2ℓ, share 4/6, children a corner path and an inward spoke), inward spokes (ℓ, 1/6,
three outward spokes) and outward spokes (ℓ, 1/6, two corner paths).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from searchtrack.core import checks
from searchtrack.core.interrupt import check_stop
from searchtrack.models.roads import RoadNetwork

#: Relative tolerance under which two chain lengths count as equal when grouping.
LENGTH_RTOL = 1e-9

#: Chains traced between two calls of :func:`~searchtrack.core.interrupt.check_stop`.
STOP_EVERY = 1024


@dataclass(frozen=True, eq=False)
class ChainGraph:
    """Directed chains of a road network and which chains follow which.

    Parameters
    ----------
    tail, head
        ``(C,)`` end nodes (junctions, dead ends or loop cuts) of each chain.
    length_m
        ``(C,)`` chain lengths (m).
    child_ptr, child_idx
        Children in CSR form: the children of chain ``c`` are
        ``child_idx[child_ptr[c]:child_ptr[c + 1]]``; every chain has at least one.
    path_ptr, path_nodes
        The node path of each chain in CSR form (tail first, head last).
    """

    tail: NDArray[np.int64]
    head: NDArray[np.int64]
    length_m: NDArray[np.float64]
    child_ptr: NDArray[np.int64]
    child_idx: NDArray[np.int64]
    path_ptr: NDArray[np.int64]
    path_nodes: NDArray[np.int64]

    @property
    def n_chains(self) -> int:
        """Number of directed chains ``C``."""
        return int(self.length_m.size)

    @cached_property
    def fanout(self) -> NDArray[np.int64]:
        """``(C,)`` number of children ``F`` of each chain: a mode leaving it splits into ``F``."""
        return checks.readonly(np.diff(self.child_ptr))

    @cached_property
    def share(self) -> NDArray[np.float64]:
        """``(C,)`` probability that a uniformly placed target starts on each chain (its share of
        the directed road length, Assumption 4)."""
        return checks.readonly(self.length_m / self.length_m.sum())

    def children(self, chain: int) -> NDArray[np.int64]:
        """Children of ``chain``."""
        return self.child_idx[self.child_ptr[chain]:self.child_ptr[chain + 1]]

    def path(self, chain: int) -> NDArray[np.int64]:
        """Node path of ``chain``, tail to head."""
        return self.path_nodes[self.path_ptr[chain]:self.path_ptr[chain + 1]]


def chain_graph(network: RoadNetwork) -> ChainGraph:
    """Merge pass-through nodes of ``network`` into directed chains (§5.3, Fig. 6).

    Parameters
    ----------
    network
        Any road network (two-way roads). Degree-2 nodes are merged; junctions (degree ≥ 3) and
        dead ends (degree 1) end chains.

    Returns
    -------
    The chains, their lengths, node paths and children under the no-U-turn rule.

    Raises
    ------
    StopRequested
        On a stop request inside :func:`~searchtrack.core.interrupt.stops_raise`.
    """
    m = network.n_edges
    tail = np.concatenate([network.edges[:, 0], network.edges[:, 1]])  # directed edge d, d + m
    head = np.concatenate([network.edges[:, 1], network.edges[:, 0]])
    length = np.concatenate([network.lengths_m, network.lengths_m])
    reverse = np.concatenate([np.arange(m, 2 * m), np.arange(m)])
    order = np.argsort(tail, kind="stable")
    out_ptr = np.searchsorted(tail[order], np.arange(network.n_nodes + 1))
    degree = network.degree
    cut = np.asarray(degree != 2)
    while True:
        chains = _trace_chains(tail, head, reverse, order, out_ptr, cut)
        used = np.zeros(2 * m, dtype=bool)
        for chain in chains:
            used[chain] = True
        if used.all():
            break
        cut[int(tail[~used].min())] = True     # a loop of pass-through nodes only
    first = np.array([c[0] for c in chains], dtype=np.int64)
    last = np.array([c[-1] for c in chains], dtype=np.int64)
    chain_of_first = np.full(2 * m, -1, dtype=np.int64)
    chain_of_first[first] = np.arange(len(chains))
    children: list[NDArray[np.int64]] = []
    for i, d in enumerate(last):
        if i % STOP_EVERY == 0:
            check_stop()
        leaving = order[out_ptr[head[d]]:out_ptr[head[d] + 1]]
        onward = leaving[leaving != reverse[d]]
        children.append(chain_of_first[onward if onward.size else np.array([reverse[d]])])
    sizes = np.array([len(c) for c in chains], dtype=np.int64)
    flat = np.concatenate([np.asarray(c, dtype=np.int64) for c in chains])
    nodes = np.insert(tail[flat], np.cumsum(sizes), head[last])  # each chain's tails, its head
    return ChainGraph(
        tail=checks.readonly(tail[first]),
        head=checks.readonly(head[last]),
        length_m=checks.readonly(np.add.reduceat(length[flat], np.cumsum(sizes) - sizes)),
        child_ptr=checks.readonly(np.concatenate([[0], np.cumsum([c.size for c in children])])),
        child_idx=checks.readonly(np.concatenate(children).astype(np.int64)),
        path_ptr=checks.readonly(np.concatenate([[0], np.cumsum(sizes + 1)])),
        path_nodes=checks.readonly(nodes.astype(np.int64)),
    )


def _trace_chains(tail: NDArray[np.int64], head: NDArray[np.int64], reverse: NDArray[np.int64],
                  order: NDArray[np.intp], out_ptr: NDArray[np.intp],
                  cut: NDArray[np.bool_]) -> list[list[int]]:
    """Directed-edge lists of the chains that start at a cut node, each followed through
    uncut (pass-through) nodes to the next cut node."""
    chains: list[list[int]] = []
    for i, node in enumerate(np.flatnonzero(cut)):
        if i % STOP_EVERY == 0:
            check_stop()
        for d in order[out_ptr[node]:out_ptr[node + 1]]:
            chain = [int(d)]
            while not cut[head[chain[-1]]]:
                leaving = order[out_ptr[head[chain[-1]]]:out_ptr[head[chain[-1]] + 1]]
                chain.append(int(leaving[leaving != reverse[chain[-1]]][0]))
            chains.append(chain)
    return chains


@dataclass(frozen=True)
class Subdivision:
    """A group of chains a splitting mode cannot tell apart (§5.3, Fig. 6–7).

    Parameters
    ----------
    members
        Indices of the chains in the group.
    length_m
        Their common length (m).
    share
        Probability ``π`` that a uniformly placed target starts in the group (level 1 of Fig. 7).
    children
        Subdivision index of each child of any member, with repeats (level 2 of Fig. 7); a mode
        leaving the group splits into ``len(children)`` equal parts.
    """

    members: tuple[int, ...]
    length_m: float
    share: float
    children: tuple[int, ...]

    @property
    def fanout(self) -> int:
        """Number of children ``F``."""
        return len(self.children)


def subdivisions(graph: ChainGraph, *, grouped: bool = True) -> tuple[Subdivision, ...]:
    """Group the chains of ``graph`` into subdivisions (§5.3).

    Parameters
    ----------
    graph
        The chains of a road map.
    grouped
        Group chains of equal length whose children fall in the same groups (refined until stable);
        with ``False`` every chain is its own subdivision. Both give the same mode probabilities.

    Returns
    -------
    Subdivisions ordered by decreasing share, then length.

    Raises
    ------
    StopRequested
        On a stop request inside :func:`~searchtrack.core.interrupt.stops_raise`.
    """
    n = graph.n_chains
    if not grouped:
        colour = np.arange(n)
    else:
        order = np.argsort(graph.length_m, kind="stable")
        step = np.diff(graph.length_m[order]) > LENGTH_RTOL * float(graph.length_m.max())
        colour = np.empty(n, dtype=np.int64)
        colour[order] = np.concatenate([[0], np.cumsum(step)])
        colour = _refine(graph, colour)
    count = int(colour.max()) + 1
    by_colour = np.argsort(colour, kind="stable")
    bounds = np.searchsorted(colour[by_colour], np.arange(count + 1))
    groups = [by_colour[bounds[g]:bounds[g + 1]] for g in range(count)]
    share = np.bincount(colour, weights=graph.share, minlength=count)
    ranked = sorted(range(count),
                    key=lambda g: (-share[g], -graph.length_m[groups[g][0]], groups[g][0]))
    rank = np.empty(count, dtype=np.int64)
    rank[ranked] = np.arange(count)
    out = []
    for g in ranked:
        first = int(groups[g][0])
        out.append(Subdivision(
            members=tuple(int(c) for c in groups[g]),
            length_m=float(graph.length_m[groups[g]].mean()),
            share=float(share[g]),
            children=tuple(sorted(rank[colour[graph.children(first)]].tolist())),
        ))
    return tuple(out)


def _refine(graph: ChainGraph, colour: NDArray[np.int64]) -> NDArray[np.int64]:
    """Split colour classes by the multiset of their children's colours until stable (colour
    refinement): chains of one final colour have identical mode-splitting futures."""
    n = graph.n_chains
    parent = np.repeat(np.arange(n), graph.fanout)
    slot = 1 + np.arange(parent.size) - np.repeat(graph.child_ptr[:-1], graph.fanout)
    while True:
        check_stop()
        kid = colour[graph.child_idx]
        signature = np.full((n, int(graph.fanout.max()) + 1), -1, dtype=np.int64)
        signature[:, 0] = colour
        signature[parent, slot] = kid[np.lexsort((kid, parent))]
        refined = np.unique(signature, axis=0, return_inverse=True)[1].reshape(-1)
        if refined.max() == colour.max():
            return colour
        colour = refined
