"""The road network as an undirected graph with planar node coordinates (thesis 001, §2.1).

Nodes are points on the roads, ``spacing_m`` apart along each road when the network was built by
:func:`~searchtrack.models.road_builder.network_from_polylines` (and so by
:func:`~searchtrack.models.osm.read_osm` and the synthetic generators). Edge lengths are distances
along the road. The matrices follow the thesis: adjacency ``A`` (2.2), degree ``D`` (2.3),
incidence ``B`` (one +1 and one −1 per column) and Laplacian ``L = D − A = B Bᵀ`` (2.4).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from functools import cached_property

import networkx as nx
import numpy as np
import scipy.sparse as sp
from numpy.typing import ArrayLike, NDArray
from scipy.sparse import csgraph
from scipy.spatial import ConvexHull, QhullError, cKDTree

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.projection import LocalProjection

M2_PER_KM2 = 1.0e6
M2_PER_MI2 = 1609.344**2


@dataclass(frozen=True, eq=False)
class RoadNetwork:
    """An undirected road graph: node coordinates, edges and edge lengths.

    Edges are stored with ``edges[k, 0] < edges[k, 1]``, sorted; duplicates and self-loops are
    refused. The network need not be connected (see :attr:`n_components`), but the builders keep
    only the largest connected component.

    Parameters
    ----------
    coords
        ``(n, 2)`` planar node coordinates in metres (x east, y north).
    edges
        ``(m, 2)`` node-index pairs, ``m ≥ 1``.
    lengths_m
        ``(m,)`` positive edge lengths in metres (along the road, so at least the straight-line
        distance between the end nodes).
    source
        Where the network came from: a file name, or a description of a synthetic network.
    spacing_m
        The node spacing the network was resampled to, if any.
    projection
        The lon/lat → metres projection used for ``coords`` (``None`` for synthetic networks).
    """

    coords: NDArray[np.float64]
    edges: NDArray[np.int64]
    lengths_m: NDArray[np.float64]
    source: str = ""
    spacing_m: float | None = None
    projection: LocalProjection | None = field(default=None)

    def __post_init__(self) -> None:
        coords = np.asarray(self.coords, dtype=np.float64)
        if coords.ndim != 2 or coords.shape[1] != 2 or coords.shape[0] < 2:
            raise InvalidInputError("coords", self.coords, "must have shape (n, 2) with n ≥ 2")
        if not np.all(np.isfinite(coords)):
            raise InvalidInputError("coords", self.coords, "must be finite")
        n = coords.shape[0]
        edges = np.asarray(self.edges)
        if edges.size == 0:
            raise InvalidInputError("edges", self.edges, "a road network needs at least one edge")
        if edges.ndim != 2 or edges.shape[1] != 2 or edges.dtype.kind not in "iu":
            raise InvalidInputError("edges", self.edges, "must be an (m, 2) integer array")
        edges = edges.astype(np.int64)
        if edges.min() < 0 or edges.max() >= n:
            raise InvalidInputError("edges", self.edges, f"node indices must be in [0, {n})")
        if np.any(edges[:, 0] == edges[:, 1]):
            raise InvalidInputError("edges", self.edges, "self-loops are not allowed")
        lengths = np.asarray(self.lengths_m, dtype=np.float64)
        if lengths.shape != (edges.shape[0],):
            raise InvalidInputError("lengths_m", self.lengths_m, f"must have shape ({len(edges)},)")
        if not np.all(np.isfinite(lengths)) or np.any(lengths <= 0):
            raise InvalidInputError("lengths_m", self.lengths_m, "must be finite and positive")
        edges = np.sort(edges, axis=1)
        order = np.lexsort((edges[:, 1], edges[:, 0]))
        edges, lengths = edges[order], lengths[order]
        if np.any(np.all(edges[1:] == edges[:-1], axis=1)):
            raise InvalidInputError("edges", self.edges, "duplicate edges are not allowed")
        if self.spacing_m is not None:
            validate_spacing(self.spacing_m)
        set_ = object.__setattr__
        set_(self, "coords", checks.readonly(coords))
        set_(self, "edges", checks.readonly(edges))
        set_(self, "lengths_m", checks.readonly(lengths))
        set_(self, "spacing_m", None if self.spacing_m is None else float(self.spacing_m))

    # ----- sizes -----------------------------------------------------------------------------

    @property
    def n_nodes(self) -> int:
        """Number of nodes ``N``."""
        return int(self.coords.shape[0])

    @property
    def n_edges(self) -> int:
        """Number of (undirected) edges ``M``."""
        return int(self.edges.shape[0])

    @property
    def total_length_m(self) -> float:
        """Total road length (m)."""
        return float(self.lengths_m.sum())

    # ----- matrices (thesis §2.1) ------------------------------------------------------------

    @cached_property
    def adjacency(self) -> sp.csr_array:
        """Symmetric ``(N, N)`` CSR matrix holding the edge length (m) of every edge both ways."""
        u, v = self.edges[:, 0], self.edges[:, 1]
        rows = np.concatenate([u, v])
        cols = np.concatenate([v, u])
        data = np.concatenate([self.lengths_m, self.lengths_m])
        return sp.csr_array((data, (rows, cols)), shape=(self.n_nodes, self.n_nodes))

    @cached_property
    def degree(self) -> NDArray[np.int64]:
        """Number of neighbours of each node (the diagonal of ``D``, (2.3))."""
        deg = np.bincount(self.edges.reshape(-1), minlength=self.n_nodes).astype(np.int64)
        deg.setflags(write=False)
        return deg

    @cached_property
    def incidence(self) -> sp.csr_array:
        """``(N, M)`` incidence ``B``: column ``k`` is +1 at ``edges[k, 0]`` and −1 at
        ``edges[k, 1]``."""
        m = self.n_edges
        rows = self.edges.T.reshape(-1)
        cols = np.tile(np.arange(m), 2)
        data = np.concatenate([np.ones(m), -np.ones(m)])
        return sp.csr_array((data, (rows, cols)), shape=(self.n_nodes, m))

    @cached_property
    def laplacian(self) -> sp.csr_array:
        """Unweighted Laplacian ``L = D − A = B Bᵀ`` (2.4), ``A`` being 0/1, as in the thesis."""
        return self.weighted_laplacian(np.ones(self.n_edges))

    def weighted_laplacian(self, edge_weight: ArrayLike) -> sp.csr_array:
        """Laplacian ``B diag(w) Bᵀ`` with one non-negative weight per edge.

        With ``w = 1/lengths_m**2`` this is the finite-difference ``−∇²`` of (2.6) on a network of
        uneven spacing; with ``w = 1`` it is :attr:`laplacian`.
        """
        w = np.asarray(edge_weight, dtype=np.float64)
        if w.shape != (self.n_edges,) or not np.all(np.isfinite(w)) or np.any(w < 0):
            raise InvalidInputError(
                "edge_weight", edge_weight, f"must be finite, non-negative, shape ({self.n_edges},)"
            )
        b = self.incidence
        return sp.csr_array(b @ sp.diags_array(w) @ b.T)

    # ----- connectivity and intersections ----------------------------------------------------

    @cached_property
    def _components(self) -> tuple[int, NDArray[np.int32]]:
        count, labels = csgraph.connected_components(self.adjacency, directed=False)
        return int(count), labels

    @property
    def n_components(self) -> int:
        """Number of connected components."""
        return self._components[0]

    @property
    def is_connected(self) -> bool:
        """Whether every node can reach every other."""
        return self.n_components == 1

    def largest_component(self) -> RoadNetwork:
        """The sub-network of the largest connected component (``self`` if connected)."""
        count, labels = self._components
        if count == 1:
            return self
        keep = labels == np.argmax(np.bincount(labels))
        new_index = np.cumsum(keep) - 1
        edge_keep = keep[self.edges[:, 0]]
        return RoadNetwork(
            coords=self.coords[keep],
            edges=new_index[self.edges[edge_keep]],
            lengths_m=self.lengths_m[edge_keep],
            source=self.source,
            spacing_m=self.spacing_m,
            projection=self.projection,
        )

    @cached_property
    def intersections(self) -> NDArray[np.int64]:
        """Indices of the intersection nodes, those of degree ≥ 3 (the thesis does not define an
        intersection)."""
        idx = np.flatnonzero(self.degree >= 3).astype(np.int64)
        idx.setflags(write=False)
        return idx

    @property
    def n_intersections(self) -> int:
        """Number of intersections (nodes of degree ≥ 3)."""
        return int(self.intersections.size)

    @cached_property
    def hull_area_m2(self) -> float:
        """Area (m²) of the convex hull of the nodes; 0 if they are collinear."""
        try:
            return float(ConvexHull(self.coords).volume)
        except QhullError:
            return 0.0

    @property
    def bbox_area_m2(self) -> float:
        """Area (m²) of the axis-aligned bounding box of the nodes."""
        span = self.coords.max(axis=0) - self.coords.min(axis=0)
        return float(span[0] * span[1])

    @property
    def intersection_density_per_km2(self) -> float:
        """Intersections per km² of the nodes' convex hull (thesis Table 6.1 uses the hull, in
        mi⁻²); NaN when the hull is degenerate."""
        area = self.hull_area_m2
        return self.n_intersections / (area / M2_PER_KM2) if area > 0 else math.nan

    @property
    def intersection_density_per_mi2(self) -> float:
        """Intersections per square mile of the convex hull, the thesis's unit (Table 6.1)."""
        area = self.hull_area_m2
        return self.n_intersections / (area / M2_PER_MI2) if area > 0 else math.nan

    # ----- distances -------------------------------------------------------------------------

    def _node_indices(self, name: str, nodes: ArrayLike) -> NDArray[np.int64]:
        arr = np.atleast_1d(np.asarray(nodes))
        if arr.ndim != 1 or arr.size == 0 or arr.dtype.kind not in "iu":
            raise InvalidInputError(name, nodes, "must be one or more integer node indices")
        if arr.min() < 0 or arr.max() >= self.n_nodes:
            raise InvalidInputError(name, nodes, f"node indices must be in [0, {self.n_nodes})")
        return arr.astype(np.int64)

    def shortest_paths(
        self, sources: ArrayLike, *, limit_m: float = math.inf
    ) -> NDArray[np.float64]:
        """Road distances (m) from each source to every node, by Dijkstra.

        Parameters
        ----------
        sources
            One node index or a sequence of them (``k`` sources).
        limit_m
            Stop searching beyond this distance; farther nodes get ``inf``.

        Returns
        -------
        ``(k, N)`` distances, ``inf`` where unreachable.
        """
        src = self._node_indices("sources", sources)
        if not isinstance(limit_m, (int, float)) or math.isnan(limit_m) or limit_m < 0:
            raise InvalidInputError("limit_m", limit_m, "must be a non-negative number")
        dist = csgraph.dijkstra(self.adjacency, directed=False, indices=src, limit=limit_m)
        return np.asarray(dist, dtype=np.float64).reshape(src.size, self.n_nodes)

    def shortest_path(self, source: int, target: int) -> tuple[NDArray[np.int64], float]:
        """Node indices of a shortest path from ``source`` to ``target`` and its length (m).

        Returns an empty path and ``inf`` when ``target`` is unreachable.
        """
        s = int(self._node_indices("source", source)[0])
        t = int(self._node_indices("target", target)[0])
        dist, pred = csgraph.dijkstra(
            self.adjacency, directed=False, indices=s, return_predecessors=True
        )
        if not math.isfinite(dist[t]):
            return np.empty(0, dtype=np.int64), math.inf
        path = [t]
        while path[-1] != s:
            path.append(int(pred[path[-1]]))
        return np.array(path[::-1], dtype=np.int64), float(dist[t])

    @cached_property
    def _tree(self) -> cKDTree:
        return cKDTree(self.coords)

    def nearest_nodes(self, xy_m: ArrayLike) -> NDArray[np.int64]:
        """Index of the node nearest (straight line) to each planar point ``(k, 2)`` (m)."""
        xy = np.asarray(xy_m, dtype=np.float64)
        if xy.shape[-1:] != (2,) or not np.all(np.isfinite(xy)):
            raise InvalidInputError("xy_m", xy_m, "must be finite points of shape (k, 2)")
        _, idx = self._tree.query(xy.reshape(-1, 2))
        return np.asarray(idx, dtype=np.int64)

    def nodes_within(
        self, xy_m: ArrayLike, radius_m: ArrayLike
    ) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The nodes within ``radius_m`` (straight line, inclusive) of each of ``k`` points.

        ``radius_m`` is one radius or one per point. Returns flat ``(point, node)`` index pairs,
        grouped by point in order and by node index within a point: the footprint node sets
        ``𝒩_k^j`` of §5.2 for UAVs at ``xy_m``.
        """
        xy = np.asarray(xy_m, dtype=np.float64).reshape(-1, 2)
        if not np.all(np.isfinite(xy)):
            raise InvalidInputError("xy_m", xy_m, "must be finite points of shape (k, 2)")
        r = np.broadcast_to(np.asarray(radius_m, dtype=np.float64), (xy.shape[0],))
        if not np.all(np.isfinite(r) & (r >= 0)):
            raise InvalidInputError("radius_m", radius_m, "must be finite and ≥ 0 (m)")
        hits = [np.sort(np.asarray(h, dtype=np.int64))
                for h in self._tree.query_ball_point(xy, r)] if xy.size else []
        sizes = np.array([h.size for h in hits], dtype=np.int64)
        point = np.repeat(np.arange(sizes.size, dtype=np.int64), sizes)
        node = np.concatenate(hits) if hits else np.empty(0, dtype=np.int64)
        return point, node.astype(np.int64)

    # ----- views -----------------------------------------------------------------------------

    def to_networkx(self) -> nx.Graph:
        """A new networkx ``Graph``: node attribute ``pos`` (x, y) in m, edge attribute
        ``length`` in m."""
        g = nx.Graph(source=self.source, spacing_m=self.spacing_m)
        g.add_nodes_from((i, {"pos": (float(x), float(y))}) for i, (x, y) in enumerate(self.coords))
        g.add_edges_from(
            (int(u), int(v), {"length": float(w)})
            for (u, v), w in zip(self.edges, self.lengths_m, strict=True)
        )
        return g

    def __repr__(self) -> str:
        return (
            f"RoadNetwork(source={self.source!r}, n_nodes={self.n_nodes}, n_edges={self.n_edges}, "
            f"total_length_m={self.total_length_m:.1f}, n_intersections={self.n_intersections})"
        )


def validate_spacing(spacing_m: object) -> float:
    """``spacing_m`` as a float, or :class:`InvalidInputError` unless finite and positive."""
    if (
        isinstance(spacing_m, bool)
        or not isinstance(spacing_m, (int, float, np.integer, np.floating))
        or not math.isfinite(spacing_m)
        or spacing_m <= 0
    ):
        raise InvalidInputError("spacing_m", spacing_m, "must be a finite number > 0 (metres)")
    return float(spacing_m)
