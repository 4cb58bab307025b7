"""Directed routing on a road network with a random share of one-way streets.

``read_osm`` keeps roads undirected (thesis 001 ignores ``oneway`` tags), yet one-way streets are
what gives city traffic a direction that depends on position, the structure paper 003's GP
velocity field learns from taxi traces. :func:`one_way_roads` makes a random share of the
*streets* one-way, a street being a maximal chain of edges joined at nodes of degree 2 (so a
whole block between intersections gets one direction), and routes vehicles by shortest paths on
the resulting directed graph. Only nodes of its largest strongly connected component are offered
as trip ends, so every trip has a path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray
from scipy.sparse import csgraph

from searchtrack.core.types import IntArray
from searchtrack.models.roads import RoadNetwork


def street_labels(network: RoadNetwork) -> IntArray:
    """``(m,)`` street index of each edge: edges sharing a node of degree 2 share a street."""
    m = network.n_edges
    node = network.edges.reshape(-1)
    edge = np.repeat(np.arange(m, dtype=np.int64), 2)
    order = np.argsort(node, kind="stable")
    sn, se = node[order], edge[order]
    link = (sn[:-1] == sn[1:]) & (network.degree[sn[:-1]] == 2)
    a, b = se[:-1][link], se[1:][link]
    graph = sp.coo_array((np.ones(a.size), (a, b)), shape=(m, m))
    _, labels = csgraph.connected_components(graph, directed=False)
    return np.asarray(labels, dtype=np.int64)


def _orient(network: RoadNetwork, edges: IntArray, reverse: bool) -> list[tuple[int, int]]:
    """Arcs ``(tail, head)`` along one street, walked from one end (any node for a loop)."""
    touching: dict[int, list[int]] = {}
    for e in edges.tolist():
        for v in network.edges[e].tolist():
            touching.setdefault(v, []).append(e)
    ends = [v for v, es in touching.items() if len(es) == 1]
    node = min(ends) if ends else min(touching)
    used: set[int] = set()
    arcs = []
    while True:
        nxt = [e for e in touching[node] if e not in used]
        if not nxt:
            break
        e = nxt[0]
        used.add(e)
        u, v = network.edges[e].tolist()
        head = v if u == node else u
        arcs.append((head, node) if reverse else (node, head))
        node = head
    return arcs


@dataclass(frozen=True, eq=False)
class OneWayRoads:
    """A directed road graph: ``adjacency[u, v]`` is the length (m) of the arc ``u → v``.

    Attributes
    ----------
    network
        The undirected road network.
    adjacency
        ``(n, n)`` CSR matrix of arc lengths.
    one_way
        ``(m,)`` whether each edge is one-way.
    reachable
        Sorted indices of the nodes of the largest strongly connected component.
    """

    network: RoadNetwork
    adjacency: sp.csr_array
    one_way: NDArray[np.bool_]
    reachable: IntArray

    def path(self, source: int, target: int) -> IntArray:
        """Node indices of a shortest directed path (both ends in :attr:`reachable`)."""
        _, pred = csgraph.dijkstra(self.adjacency, directed=True, indices=source,
                                   return_predecessors=True)
        out = [target]
        while out[-1] != source:
            out.append(int(pred[out[-1]]))
        return np.array(out[::-1], dtype=np.int64)


def one_way_roads(network: RoadNetwork, fraction: float, rng: np.random.Generator) -> OneWayRoads:
    """Make each street one-way with probability ``fraction`` (random direction), the rest
    two-way; ``fraction`` in ``[0, 1]`` is checked by the caller."""
    labels = street_labels(network)
    n_streets = int(labels.max()) + 1
    chosen = rng.random(n_streets) < fraction
    reverse = rng.random(n_streets) < 0.5
    one_way = chosen[labels]
    two = network.edges[~one_way]
    tails = [two[:, 0], two[:, 1]]
    heads = [two[:, 1], two[:, 0]]
    if np.any(one_way):
        order = np.argsort(labels, kind="stable")
        bounds = np.searchsorted(labels[order], np.arange(n_streets + 1))
        arcs = [arc for s in np.flatnonzero(chosen).tolist()
                for arc in _orient(network, order[bounds[s]:bounds[s + 1]], bool(reverse[s]))]
        arr = np.array(arcs, dtype=np.int64).reshape(-1, 2)
        tails.append(arr[:, 0])
        heads.append(arr[:, 1])
    tail, head = np.concatenate(tails), np.concatenate(heads)
    length = np.asarray(network.adjacency[tail, head], dtype=np.float64).reshape(-1)
    n = network.n_nodes
    adjacency = sp.csr_array((length, (tail, head)), shape=(n, n))
    _, comp = csgraph.connected_components(adjacency, directed=True, connection="strong")
    biggest = np.argmax(np.bincount(comp))
    one_way.setflags(write=False)
    return OneWayRoads(network, adjacency, one_way,
                       np.flatnonzero(comp == biggest).astype(np.int64))
