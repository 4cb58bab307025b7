"""Exact road (shortest-path) distances between node sets, through the graph's chains.

A road network resampled every 10 m is mostly chains of degree-2 nodes between a few junctions
(the Aguascalientes map: 8602 nodes, under a thousand junctions). Every path from a chain's
interior node leaves the chain through one of its two end junctions, so

    d(u, v) = min over ends x of u, y of v of  off_x(u) + D(x, y) + off_y(v)

(and, for u and v on the same chain, also ``|pos(u) − pos(v)|`` along it), where ``D`` is the
shortest-path distance on the small *junction graph*: one node per junction, one edge per chain
(its length) or per junction-to-junction road edge. This is exact, not an approximation: it is
Dijkstra's answer, with Dijkstra run on the junction graph instead of the road graph, then a
vectorised minimum over four terms. When there are at most ``dense_junction_limit`` junctions
(default 3000, i.e. ≤ 72 MB) all of ``D`` is computed once at construction (≈ 90 ms for the 742
junctions of Aguascalientes) and a query is pure indexing; otherwise each query runs Dijkstra
from the end junctions of its sources only (≈ 0.12 ms per junction there).

Junctions are the nodes of degree ≠ 2, plus the lowest-index node of any component that is a
bare cycle (all degrees 2), so that every chain is a simple path.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import csgraph

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.roads import RoadNetwork

log = logging.getLogger("searchtrack.models.road_metric")



@dataclass(frozen=True, eq=False)
class RoadMetric:
    """Shortest-path distances (m) on ``network`` between node sets, via its chains.

    Build once per network and reuse: the associators hold one. All derived arrays are
    read-only.

    Parameters
    ----------
    network
        The road graph.
    dense_junction_limit
        Precompute all junction-to-junction distances when there are at most this many
        junctions (``0``: never).

    Attributes
    ----------
    junctions
        Node indices of the junctions, ascending.
    end_a, end_b
        ``(n,)`` junction index (into ``junctions``) of each node's two chain ends; a junction's
        own index for a junction.
    off_a, off_b
        ``(n,)`` distance (m) along the chain from each node to ``end_a`` / ``end_b``; 0 for a
        junction.
    chain
        ``(n,)`` chain index of each interior node, −1 for a junction.
    component
        ``(n,)`` connected-component label of each node.
    junction_graph
        ``(J, J)`` upper-triangular CSR junction graph (edge lengths in m).
    junction_distances
        ``(J, J)`` all-pairs junction distances (m), or ``None`` above the limit.
    lower_bound_factor
        ``κ = min(1, min_e length_e / ‖ψ(u_e) − ψ(v_e)‖)``: ``d(u, v) ≥ κ ‖ψ(u) − ψ(v)‖`` for
        all nodes (triangle inequality edge by edge); 1 when every road edge is at least as
        long as the straight line, as for the builders' networks.
    """

    network: RoadNetwork
    dense_junction_limit: int = 3000
    junctions: IntArray = field(init=False, repr=False)
    end_a: IntArray = field(init=False, repr=False)
    end_b: IntArray = field(init=False, repr=False)
    off_a: FloatArray = field(init=False, repr=False)
    off_b: FloatArray = field(init=False, repr=False)
    chain: IntArray = field(init=False, repr=False)
    component: IntArray = field(init=False, repr=False)
    junction_graph: sp.csr_array = field(init=False, repr=False)
    junction_distances: FloatArray | None = field(init=False, repr=False)
    lower_bound_factor: float = field(init=False)

    def __post_init__(self) -> None:
        net = self.network
        if not isinstance(net, RoadNetwork):
            raise InvalidInputError("network", net, "must be a RoadNetwork")
        limit = self.dense_junction_limit
        if isinstance(limit, bool) or not isinstance(limit, (int, np.integer)) or limit < 0:
            raise InvalidInputError("dense_junction_limit", limit, "must be an integer ≥ 0")
        _, label = csgraph.connected_components(net.adjacency, directed=False)
        label = label.astype(np.int64)
        junctions = np.flatnonzero(_junction_mask(net, label)).astype(np.int64)
        end_a, end_b, off_a, off_b, chain, (ju, jv, jl) = _chains(net, junctions)
        set_ = object.__setattr__
        set_(self, "junctions", checks.readonly(junctions, copy=False))
        set_(self, "end_a", checks.readonly(end_a, copy=False))
        set_(self, "end_b", checks.readonly(end_b, copy=False))
        set_(self, "off_a", checks.readonly(off_a, copy=False))
        set_(self, "off_b", checks.readonly(off_b, copy=False))
        set_(self, "chain", checks.readonly(chain, copy=False))
        set_(self, "component", checks.readonly(label, copy=False))
        graph = _junction_graph(ju, jv, jl, junctions.size)
        set_(self, "junction_graph", graph)
        dense = None
        if junctions.size <= limit:
            dense = checks.readonly(np.asarray(csgraph.dijkstra(graph, directed=False),
                                               dtype=np.float64), copy=False)
        set_(self, "junction_distances", dense)
        set_(self, "lower_bound_factor", _lower_bound_factor(net))
        log.debug("road metric: %d nodes, %d junctions, %d junction-graph edges", net.n_nodes,
                  junctions.size, graph.nnz)

    @property
    def n_nodes(self) -> int:
        """Number of road nodes."""
        return self.network.n_nodes

    def _nodes(self, name: str, nodes: ArrayLike) -> IntArray:
        arr = np.asarray(nodes)
        if arr.ndim != 1 or (arr.size and arr.dtype.kind not in "iu"):
            raise InvalidInputError(name, nodes, "must be a 1-D array of integer node indices")
        if arr.size and (arr.min() < 0 or arr.max() >= self.n_nodes):
            raise InvalidInputError(name, nodes, f"node indices must be in [0, {self.n_nodes})")
        return arr.astype(np.int64)

    def from_nodes(self, sources: ArrayLike) -> SourceDistances:
        """Distances from ``sources``, ready for any targets: the junction-graph rows of their
        end junctions (from the precomputed table, or one Dijkstra per distinct end)."""
        src = self._nodes("sources", sources)
        if self.junction_distances is not None:
            return SourceDistances(self, src, self.junction_distances, self.end_a[src],
                                   self.end_b[src])
        ends = np.unique(np.concatenate([self.end_a[src], self.end_b[src]]))
        rows = (csgraph.dijkstra(self.junction_graph, directed=False, indices=ends)
                if ends.size else np.empty((0, self.junctions.size)))
        rows = np.asarray(rows, dtype=np.float64).reshape(ends.size, self.junctions.size)
        return SourceDistances(self, src, rows, np.searchsorted(ends, self.end_a[src]),
                               np.searchsorted(ends, self.end_b[src]))

    def distances(self, sources: ArrayLike, targets: ArrayLike) -> FloatArray:
        """``(len(sources), len(targets))`` road distances (m), ``inf`` across components."""
        return self.from_nodes(sources).to(targets)


@dataclass(frozen=True, eq=False)
class SourceDistances:
    """Distances from fixed ``sources`` to any targets, made by :meth:`RoadMetric.from_nodes`.

    ``rows`` holds junction-graph distances (m) from some junctions to every junction;
    ``row_a[i]`` / ``row_b[i]`` is the row of source ``i``'s ``end_a`` / ``end_b``.
    """

    metric: RoadMetric
    sources: IntArray
    rows: FloatArray
    row_a: IntArray
    row_b: IntArray

    def to(self, targets: ArrayLike, among: ArrayLike | None = None) -> FloatArray:
        """Distances (m) from ``sources[among]`` (all by default) to ``targets``.

        ``among`` holds positions in ``sources``; the result is ``(len(among), len(targets))``.
        """
        m = self.metric
        tgt = m._nodes("targets", targets)
        pick = (np.arange(self.sources.size) if among is None
                else np.asarray(among, dtype=np.int64))
        src = self.sources[pick]
        ra, rb = self.row_a[pick], self.row_b[pick]
        ta, tb = m.end_a[tgt], m.end_b[tgt]
        sa, sb = m.off_a[src][:, None], m.off_b[src][:, None]
        tao, tbo = m.off_a[tgt][None, :], m.off_b[tgt][None, :]
        out = sa + self.rows[np.ix_(ra, ta)] + tao
        np.minimum(out, sa + self.rows[np.ix_(ra, tb)] + tbo, out=out)
        np.minimum(out, sb + self.rows[np.ix_(rb, ta)] + tao, out=out)
        np.minimum(out, sb + self.rows[np.ix_(rb, tb)] + tbo, out=out)
        cs, ct = m.chain[src][:, None], m.chain[tgt][None, :]
        same = (cs == ct) & (cs >= 0)
        if same.any():
            direct = np.abs(sa - tao)  # both measured from the same end_a
            out[same] = np.minimum(out[same], direct[same])
        return out


def _junction_mask(network: RoadNetwork, label: IntArray) -> NDArray[np.bool_]:
    """Nodes of degree ≠ 2, plus the lowest-index node of every bare-cycle component."""
    n = network.n_nodes
    is_junction = np.asarray(network.degree != 2, dtype=bool)
    has_junction = np.zeros(int(label.max()) + 1, dtype=bool)
    has_junction[label[is_junction]] = True
    first = np.full(has_junction.size, n, dtype=np.int64)
    np.minimum.at(first, label, np.arange(n, dtype=np.int64))
    is_junction[first[~has_junction]] = True  # cut every bare cycle open
    return is_junction


def _chains(
    network: RoadNetwork, junctions: IntArray
) -> tuple[IntArray, IntArray, FloatArray, FloatArray, IntArray,
           tuple[IntArray, IntArray, FloatArray]]:
    """Per node: chain ends ``end_a``/``end_b`` (junction indices), offsets ``off_a``/``off_b``
    (m) and chain index; and the junction-graph edges ``(u, v, length)``.

    The interior (non-junction) nodes form disjoint simple paths, the chains; each has exactly
    two edges to junctions (its attachments, ordered by interior node then junction: 'a' first).
    Offsets along a chain come from one multi-source Dijkstra from every chain's 'a' node.
    """
    n = network.n_nodes
    is_junction = np.zeros(n, dtype=bool)
    is_junction[junctions] = True
    jid = np.full(n, -1, dtype=np.int64)
    jid[junctions] = np.arange(junctions.size, dtype=np.int64)
    u, v, length = network.edges[:, 0], network.edges[:, 1], network.lengths_m
    end_a, end_b = jid.copy(), jid.copy()
    off_a, off_b = np.zeros(n), np.zeros(n)
    chain = np.full(n, -1, dtype=np.int64)
    direct = is_junction[u] & is_junction[v]  # road edges between two junctions
    ju, jv, jl = [jid[u[direct]]], [jid[v[direct]]], [length[direct]]
    interior = np.flatnonzero(~is_junction)
    if interior.size:
        iid = np.full(n, -1, dtype=np.int64)
        iid[interior] = np.arange(interior.size, dtype=np.int64)
        inner = ~is_junction[u] & ~is_junction[v]
        g = sp.csr_array((length[inner], (iid[u[inner]], iid[v[inner]])),
                         shape=(interior.size, interior.size))
        n_chains, chain_of = csgraph.connected_components(g, directed=False)
        attach = is_junction[u] ^ is_junction[v]
        node = np.where(is_junction[u], v, u)[attach]  # the interior end of the edge
        junc = np.where(is_junction[u], u, v)[attach]
        c = chain_of[iid[node]].astype(np.int64)
        if not np.array_equal(np.bincount(c, minlength=n_chains), np.full(n_chains, 2)):
            raise AssertionError("every chain must have exactly two attachments")
        order = np.lexsort((junc, node, c))
        node, junc, ell = node[order], junc[order], length[attach][order]
        along = csgraph.dijkstra(g, directed=False, indices=iid[node[0::2]], min_only=True)
        chain_len = ell[0::2] + along[iid[node[1::2]]] + ell[1::2]
        ci = chain_of[iid[interior]]
        chain[interior] = ci
        end_a[interior] = jid[junc[0::2]][ci]
        end_b[interior] = jid[junc[1::2]][ci]
        off_a[interior] = ell[0::2][ci] + along[iid[interior]]
        off_b[interior] = chain_len[ci] - off_a[interior]
        ju.append(jid[junc[0::2]])
        jv.append(jid[junc[1::2]])
        jl.append(chain_len)
    edges = (np.concatenate(ju), np.concatenate(jv), np.concatenate(jl))
    return end_a, end_b, off_a, off_b, chain, edges


def _junction_graph(u: IntArray, v: IntArray, length: FloatArray, n: int) -> sp.csr_array:
    """Undirected junction graph, one entry per pair (the shortest parallel road), no loops."""
    lo, hi = np.minimum(u, v), np.maximum(u, v)
    keep = lo != hi
    lo, hi, length = lo[keep], hi[keep], length[keep]
    order = np.lexsort((length, hi, lo))
    lo, hi, length = lo[order], hi[order], length[order]
    first = np.ones(lo.size, dtype=bool)
    first[1:] = (lo[1:] != lo[:-1]) | (hi[1:] != hi[:-1])
    return sp.csr_array((length[first], (lo[first], hi[first])), shape=(n, n))


def _lower_bound_factor(network: RoadNetwork) -> float:
    """``min(1, min_e length_e / straight_e)`` over edges with distinct end points."""
    xy = network.coords
    straight = np.linalg.norm(xy[network.edges[:, 0]] - xy[network.edges[:, 1]], axis=1)
    pos = straight > 0.0
    if not pos.any():
        return 1.0
    return float(min(1.0, float((network.lengths_m[pos] / straight[pos]).min())))
