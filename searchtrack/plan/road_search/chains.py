"""Planning over intersections: a road network with its chains of degree-2 nodes merged.

A resampled map (an OpenStreetMap extract at 10 m node spacing) has a node every few metres, so
a look-ahead of ``L`` edges covers a few tens of metres. Merging every chain of degree-2 nodes
into one edge between its end nodes (intersections, dead ends and any node the caller keeps)
makes a look-ahead step one road segment, as on the paper's hand-built grids.

The merge is exact for the road-particle motion model (Eq. 9 with the no-U-turn rule): at a
degree-2 node a particle has one successor, so it moves along the chain exactly as along the
merged edge, and at a kept node the successors are the same roads. A fine position ``(d, s)``
maps to ``(D, offset[d] + s)`` on the merged directed edge ``D`` (:meth:`ChainGraph.to_coarse`).

Two chains joining the same two nodes, or a chain that returns to its start, would be a
duplicate edge or a self-loop; such chains keep interior nodes (the middle one, or two for a
loop) so that the merged network stays simple.
"""

from __future__ import annotations

import itertools
from collections.abc import Iterable
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from searchtrack.core import checks
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.road_particles import DirectedRoads
from searchtrack.models.roads import RoadNetwork

Chain = tuple[list[int], list[int], float]  # fine nodes, fine undirected edges, length (m)


def _walk_chains(net: RoadNetwork, kept: set[int]) -> list[Chain]:
    """Every maximal chain between kept nodes, each once."""
    ptr = np.zeros(net.n_nodes + 1, dtype=np.int64)
    np.add.at(ptr, net.edges.reshape(-1) + 1, 1)
    ptr = np.cumsum(ptr)
    order = np.argsort(net.edges.reshape(-1), kind="stable")
    incident = (order // 2).tolist()  # undirected edge ids incident to each node, CSR
    ends = net.edges.tolist()
    lengths = net.lengths_m.tolist()
    ptr_l = ptr.tolist()
    seen: set[int] = set()
    chains: list[Chain] = []
    for start in sorted(kept):
        for first in incident[ptr_l[start]:ptr_l[start + 1]]:
            if first in seen:
                continue
            nodes, edges, total = [start], [], 0.0
            node, e = start, first
            while True:
                seen.add(e)
                edges.append(e)
                total += lengths[e]
                a, b = ends[e]
                node = b if a == node else a
                nodes.append(node)
                if node in kept:
                    break
                nxt = [f for f in incident[ptr_l[node]:ptr_l[node + 1]] if f != e]
                e = nxt[0]
            chains.append((nodes, edges, total))
    return chains


def _splitting_nodes(chains: list[Chain]) -> set[int]:
    """Interior nodes to keep so that no chain is a self-loop or parallel to another."""
    extra: set[int] = set()
    by_pair: dict[tuple[int, int], list[Chain]] = {}
    for chain in chains:
        nodes = chain[0]
        if nodes[0] == nodes[-1]:
            inner = nodes[1:-1]
            extra.update((inner[len(inner) // 3], inner[(2 * len(inner)) // 3]))
            continue
        pair = (min(nodes[0], nodes[-1]), max(nodes[0], nodes[-1]))
        by_pair.setdefault(pair, []).append(chain)
    for group in by_pair.values():
        group.sort(key=lambda c: len(c[0]))
        for chain in group[1:]:  # the shortest stays whole (at most one has no interior node)
            extra.add(chain[0][len(chain[0]) // 2])
    return extra


@dataclass(frozen=True, eq=False)
class ChainGraph:
    """A fine road network and its merged network of kept nodes.

    Parameters
    ----------
    fine
        The original network.
    keep
        Nodes of ``fine`` to keep besides intersections and dead ends (e.g. the UAVs' nodes).

    Attributes
    ----------
    network
        The merged network (nodes: the kept nodes; edges: the chains).
    node_ids
        ``(n_coarse,)`` the fine node of each merged node.
    coarse_of_node
        ``(n_fine,)`` the merged node of each fine node, ``-1`` for interior chain nodes.
    edge_map, offset_m
        ``(2 m_fine,)`` the merged directed edge of each fine directed edge, and the distance
        (m) from the merged edge's tail to the fine edge's tail.
    """

    fine: RoadNetwork
    keep: tuple[int, ...] = ()
    network: RoadNetwork = field(init=False, repr=False)
    node_ids: IntArray = field(init=False, repr=False)
    coarse_of_node: IntArray = field(init=False, repr=False)
    edge_map: IntArray = field(init=False, repr=False)
    offset_m: FloatArray = field(init=False, repr=False)
    _paths: tuple[IntArray, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        net = self.fine
        extra = checks.index_array("keep", list(self.keep), net.n_nodes)
        kept = set(np.flatnonzero(net.degree != 2).tolist()) | set(extra.tolist())
        if not kept:
            kept = {0}
        while True:
            chains = _walk_chains(net, kept)
            covered = {e for c in chains for e in c[1]}
            missing = sorted(set(range(net.n_edges)) - covered)
            add = _splitting_nodes(chains) if not missing else {int(net.edges[missing[0], 0])}
            if not add:
                break
            kept |= add
        node_ids = np.array(sorted(kept), dtype=np.int64)
        coarse_of = np.full(net.n_nodes, -1, dtype=np.int64)
        coarse_of[node_ids] = np.arange(node_ids.size)
        pairs = np.array([[coarse_of[c[0][0]], coarse_of[c[0][-1]]] for c in chains])
        coarse = RoadNetwork(net.coords[node_ids], pairs, np.array([c[2] for c in chains]),
                             source=f"{net.source} (chains merged)")
        index = {(int(a), int(b)): k for k, (a, b) in enumerate(coarse.edges)}
        edge_map = np.empty(2 * net.n_edges, dtype=np.int64)
        offset = np.empty(2 * net.n_edges)
        paths: list[IntArray] = [np.empty(0, dtype=np.int64)] * coarse.n_edges
        fine_ends = net.edges
        for (nodes, edges, total), (a, b) in zip(chains, pairs.tolist(), strict=True):
            k = index[(min(a, b), max(a, b))]
            forward = 2 * k if a < b else 2 * k + 1  # merged edge from nodes[0] to nodes[-1]
            paths[k] = np.array(nodes if a < b else nodes[::-1], dtype=np.int64)
            run = 0.0
            for i, e in enumerate(edges):
                fwd = 2 * e if fine_ends[e, 0] == nodes[i] else 2 * e + 1
                length = float(net.lengths_m[e])
                edge_map[fwd], offset[fwd] = forward, run
                edge_map[fwd ^ 1], offset[fwd ^ 1] = forward ^ 1, total - run - length
                run += length
        for name, value in (("network", coarse), ("node_ids", checks.readonly(node_ids)),
                            ("coarse_of_node", checks.readonly(coarse_of)),
                            ("edge_map", checks.readonly(edge_map)),
                            ("offset_m", checks.readonly(offset)),
                            ("_paths", tuple(checks.readonly(p) for p in paths))):
            object.__setattr__(self, name, value)

    def to_coarse(self, edge: IntArray, s: FloatArray) -> tuple[IntArray, FloatArray]:
        """Fine positions ``(edge, s)`` (directed edges of ``DirectedRoads(fine)``) as positions
        on the merged network's directed edges."""
        e = np.asarray(edge, dtype=np.int64)
        return self.edge_map[e], self.offset_m[e] + np.asarray(s, dtype=np.float64)

    def fine_path(self, nodes: Iterable[int]) -> IntArray:
        """The fine nodes of a path given by merged nodes (consecutive nodes adjacent)."""
        seq = [int(n) for n in nodes]
        out = [int(self.node_ids[seq[0]])] if seq else []
        for a, b in itertools.pairwise(seq):
            k = self._edge_index(min(a, b), max(a, b))
            path = self._paths[k]
            out.extend((path if a < b else path[::-1])[1:].tolist())
        return np.array(out, dtype=np.int64)

    def _edge_index(self, a: int, b: int) -> int:
        edges = self.network.edges
        k = int(np.searchsorted(edges[:, 0] * self.network.n_nodes + edges[:, 1],
                                a * self.network.n_nodes + b))
        if k >= edges.shape[0] or edges[k, 0] != a or edges[k, 1] != b:
            raise ValueError(f"merged nodes {a} and {b} are not adjacent")
        return k

    @cached_property
    def roads(self) -> DirectedRoads:
        """The directed view of the merged network (built once)."""
        return DirectedRoads(self.network)
