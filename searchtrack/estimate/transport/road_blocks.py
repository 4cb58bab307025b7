"""Road-distance blocks for the gated pairs of an EMD matrix (thesis §4.3, Algorithm 1).

The transportation LP (4.3)–(4.7) of a tracker ``i`` and a measurement ``j`` needs the road
distances between their two truncated supports. :class:`PairBlocks` computes them for every pair
of a scan that a gate bound left standing, from the *source side* (the side whose paired
supports hold fewer nodes). A road network resampled every few metres is mostly chains of
degree-2 nodes between junctions, and every path leaves a chain through one of its two end
junctions (:class:`~searchtrack.models.road_metric.RoadMetric`), so the searches run on the
small junction graph: one Dijkstra per distinct end junction of a source signature's support
(:func:`chain_distances`), stopped

* at ``limit`` (m): targets farther away read ``inf``, meaning "farther than ``limit``";
* as soon as every end junction of the source's partners' supports is settled.

A node's distance is then the least of its four end-to-end sums (and, on a shared chain, the
distance along it). An end junction beyond ``limit`` is not settled, but every sum through it
exceeds ``limit`` too, so a distance within ``limit`` is exact and one beyond it reads ``inf``.

A source signature's partners share its Dijkstra runs: one ``(|S_source|, |targets|)`` block
per source signature, which each pair slices. When the network's
:class:`~searchtrack.models.road_metric.RoadMetric` holds all junction-to-junction distances (a
map with few junctions between long chains), blocks come from it instead, exact, by one kernel pass
alone. With a finite ``limit`` the block of a pair is exact
where finite and a *lower bound* ``limit`` where capped (:meth:`PairBlocks.capped`), so the EMD
under the capped costs is a lower bound on the EMD, exact when its plan uses no capped entry;
:meth:`PairBlocks.exact` gives a pair's unbounded block when it is needed.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from searchtrack.core.kernel_threads import threads_for
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.signatures import Signature
from searchtrack.estimate.transport import dijkstra_kernels as kernels
from searchtrack.models.road_metric import RoadMetric
from searchtrack.models.roads import RoadNetwork

_CSR: weakref.WeakKeyDictionary[RoadNetwork, tuple[IntArray, IntArray, FloatArray]] = (
    weakref.WeakKeyDictionary())
_JUNCTION_CSR: weakref.WeakKeyDictionary[RoadMetric, tuple[IntArray, IntArray, FloatArray]] = (
    weakref.WeakKeyDictionary())


def sorted_unique(values: IntArray) -> IntArray:
    """The distinct entries of ``values``, ascending: ``np.unique`` by a sort, which is several
    times faster than NumPy's hash-based ``unique`` on the few hundred nodes of a support."""
    out = np.sort(values)
    if out.size:
        out = out[np.concatenate(([True], out[1:] != out[:-1]))]
    return out


def graph_arrays(network: RoadNetwork) -> tuple[IntArray, IntArray, FloatArray]:
    """``(indptr, indices, lengths)`` of the network's CSR adjacency, as the kernel takes them
    (made once per network)."""
    arrays = _CSR.get(network)
    if arrays is None:
        adj = network.adjacency
        arrays = (adj.indptr.astype(np.int64), adj.indices.astype(np.int64),
                  np.ascontiguousarray(adj.data, dtype=np.float64))
        _CSR[network] = arrays
    return arrays


def junction_arrays(metric: RoadMetric) -> tuple[IntArray, IntArray, FloatArray]:
    """``(indptr, indices, lengths)`` of the metric's junction graph, both directions (made once
    per metric)."""
    arrays = _JUNCTION_CSR.get(metric)
    if arrays is None:
        graph = metric.junction_graph
        both = (graph + graph.T).tocsr()
        both.sort_indices()
        arrays = (both.indptr.astype(np.int64), both.indices.astype(np.int64),
                  np.ascontiguousarray(both.data, dtype=np.float64))
        _JUNCTION_CSR[metric] = arrays
    return arrays


def chain_distances(metric: RoadMetric, sources: IntArray, targets: IntArray,
                    limit: float = math.inf) -> FloatArray:
    """``(len(sources), len(targets))`` road distances (m) through the chains' end junctions
    (module docstring); ``inf`` beyond ``limit`` or across components."""
    src_a, src_b = metric.end_a[sources], metric.end_b[sources]
    dst_a, dst_b = metric.end_a[targets], metric.end_b[targets]
    ends = sorted_unique(np.concatenate([src_a, src_b]))
    reached = sorted_unique(np.concatenate([dst_a, dst_b]))
    indptr, indices, lengths = junction_arrays(metric)
    col = np.full(metric.junctions.size, -1, dtype=np.int64)
    col[reached] = np.arange(reached.size, dtype=np.int64)
    rows = np.full((ends.size, reached.size), math.inf)
    if ends.size and reached.size:
        kernels.bounded_rows(indptr, indices, lengths, ends, col, int(reached.size),
                             float(limit), rows)
    ra, rb = np.searchsorted(ends, src_a), np.searchsorted(ends, src_b)
    ta, tb = col[dst_a], col[dst_b]
    sa, sb = metric.off_a[sources][:, None], metric.off_b[sources][:, None]
    tao, tbo = metric.off_a[targets][None, :], metric.off_b[targets][None, :]
    out: FloatArray = np.asarray(sa + rows[np.ix_(ra, ta)] + tao, dtype=np.float64)
    np.minimum(out, sa + rows[np.ix_(ra, tb)] + tbo, out=out)
    np.minimum(out, sb + rows[np.ix_(rb, ta)] + tao, out=out)
    np.minimum(out, sb + rows[np.ix_(rb, tb)] + tbo, out=out)
    cs, ct = metric.chain[sources][:, None], metric.chain[targets][None, :]
    same = (cs == ct) & (cs >= 0)
    if same.any():
        np.minimum(out, np.where(same, np.abs(sa - tao), math.inf), out=out)
    if math.isfinite(limit):
        out[out > limit] = math.inf
    return out


def road_distances(network: RoadNetwork, sources: IntArray, targets: IntArray,
                   limit: float = math.inf) -> FloatArray:
    """``(len(sources), len(targets))`` road distances (m); ``inf`` beyond ``limit`` or across
    components. ``targets`` must be distinct."""
    indptr, indices, lengths = graph_arrays(network)
    col = np.full(network.n_nodes, -1, dtype=np.int64)
    col[targets] = np.arange(targets.size, dtype=np.int64)
    out = np.full((sources.size, targets.size), math.inf)
    if sources.size and targets.size:
        kernels.bounded_rows(indptr, indices, lengths, np.ascontiguousarray(sources, np.int64),
                             col, int(targets.size), float(limit), out)
    return out


class PairBlocks:
    """Distance blocks of the pairs ``pairs`` (rows ``(i, j)``: tracker, measurement).

    Parameters
    ----------
    metric
        The road graph's metric: its junction table when it has one, else Dijkstra on the graph.
    sig_t, sig_q
        Truncated signatures of the trackers and of the measurements.
    pairs
        ``(P, 2)`` pairs whose blocks will be asked for.
    limit
        Distance (m) beyond which Dijkstra stops; ``inf`` for exact blocks.
    """

    def __init__(self, metric: RoadMetric, sig_t: list[Signature], sig_q: list[Signature],
                 pairs: IntArray, limit: float = math.inf) -> None:
        self.metric, self.network = metric, metric.network
        self.indexed = metric.junction_distances is not None
        self.limit = math.inf if self.indexed else float(limit)
        self.sig_t, self.sig_q = sig_t, sig_q
        t_size = sum(sig_t[i].size for i in np.unique(pairs[:, 0]))
        q_size = sum(sig_q[j].size for j in np.unique(pairs[:, 1]))
        self.from_measurements = bool(q_size <= t_size)
        src_col, dst_col = (1, 0) if self.from_measurements else (0, 1)
        self.src_sigs, self.dst_sigs = (sig_q, sig_t) if self.from_measurements else (sig_t, sig_q)
        self.partners = {int(k): pairs[pairs[:, src_col] == k, dst_col]
                         for k in np.unique(pairs[:, src_col])}
        self.blocks: dict[int, tuple[IntArray, FloatArray]] = {}
        self.targets: dict[bytes, IntArray] = {}

    def source_block(self, k: int) -> tuple[IntArray, FloatArray]:
        """Target nodes (all partners of source signature ``k``, sorted) and the
        ``(|S_k|, |targets|)`` distances to them (made once per source)."""
        if k not in self.blocks:
            key = self.partners[k].tobytes()  # sources with the same partners share targets
            targets = self.targets.get(key)
            if targets is None:
                targets = sorted_unique(np.concatenate([self.dst_sigs[m].nodes
                                                        for m in self.partners[k]]))
                self.targets[key] = targets
            self.blocks[k] = targets, self._distances(self.src_sigs[k].nodes, targets,
                                                      self.limit)
        return self.blocks[k]

    def block(self, i: int, j: int) -> FloatArray:
        """``(|S_i|, |S_j|)`` road distances between tracker ``i``'s and measurement ``j``'s
        supports, ``inf`` beyond :attr:`limit` (see :meth:`capped`)."""
        k, m = (j, i) if self.from_measurements else (i, j)
        targets, dist = self.source_block(k)
        cols = np.searchsorted(targets, self.dst_sigs[m].nodes)
        return dist[:, cols].T if self.from_measurements else dist[:, cols]

    def capped(self, block: FloatArray) -> tuple[FloatArray, np.ndarray] | None:
        """``block`` with its entries beyond :attr:`limit` set to ``limit`` (lower bounds on the
        road distances) and the mask of those entries; ``None`` when none is capped (the block is
        exact) or when the limit is infinite (``inf`` entries are then true: other components)."""
        if not math.isfinite(self.limit):
            return None
        over = ~np.isfinite(block)
        if not over.any():
            return None
        return np.where(over, self.limit, block), over

    def exact(self, i: int, j: int) -> FloatArray:
        """The block of :meth:`block` without the limit: ``inf`` only across components."""
        p, q = self.sig_t[i].nodes, self.sig_q[j].nodes
        if self.from_measurements:
            return self._distances(q, p, math.inf).T
        return self._distances(p, q, math.inf)

    def _distances(self, sources: IntArray, targets: IntArray, limit: float) -> FloatArray:
        if self.indexed:
            return table_distances(self.metric, sources, targets)
        return chain_distances(self.metric, sources, targets, limit)


_TABLE_WORK = 1 << 14
"""Distances from which the junction-table pass runs on all of numba's threads: each takes four
table reads and their sums, so fewer than
:data:`~searchtrack.core.kernel_threads.PARALLEL_WORK` elements pay for the threads."""


def table_distances(metric: RoadMetric, sources: IntArray, targets: IntArray) -> FloatArray:
    """:meth:`RoadMetric.distances` of a metric with a junction table, by one kernel pass (the
    same sums, in the same order)."""
    table = metric.junction_distances
    assert table is not None
    out = np.empty((sources.size, targets.size))
    with threads_for(out.size, least=_TABLE_WORK):
        kernels.table_rows(table, metric.end_a, metric.end_b, metric.off_a, metric.off_b,
                           metric.chain, np.ascontiguousarray(sources, np.int64),
                           np.ascontiguousarray(targets, np.int64), out)
    return out
