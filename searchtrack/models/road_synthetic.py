"""Synthetic road networks for tests and experiments: a Manhattan grid and random planar roads."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.sparse import coo_array
from scipy.sparse.csgraph import minimum_spanning_tree
from scipy.spatial import Delaunay

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.models.road_builder import network_from_polylines
from searchtrack.models.roads import RoadNetwork


def grid_network(
    rows: int, cols: int, block_m: float = 100.0, spacing_m: float = 10.0
) -> RoadNetwork:
    """A ``rows × cols`` grid of intersections ``block_m`` apart, roads resampled every
    ``spacing_m``.

    Intersection ``(r, c)`` is at ``(c·block_m, r·block_m)`` and is node ``c·rows + r``
    (:func:`grid_node`; the intersections come first, column by column, then the nodes between
    them). With ``k = ⌈block_m/spacing_m⌉``
    pieces per block there are ``rows·cols + (k−1)·b`` nodes and ``k·b`` edges of length
    ``block_m/k``, where ``b = rows·(cols−1) + cols·(rows−1)`` blocks; the nodes of degree ≥ 3
    are the ``rows·cols − 4`` non-corner intersections when ``rows, cols ≥ 3``.
    """
    r = checks.count("rows", rows, 1)
    c = checks.count("cols", cols, 1)
    if r * c < 2:
        raise InvalidInputError("rows", rows, "a grid needs at least 2 intersections")
    block = checks.positive("block_m", block_m)
    polylines: list[NDArray[np.float64]] = []
    for i in range(r):
        for j in range(c):
            here = (j * block, i * block)
            if j + 1 < c:
                polylines.append(np.array([here, ((j + 1) * block, i * block)]))
            if i + 1 < r:
                polylines.append(np.array([here, (j * block, (i + 1) * block)]))
    return network_from_polylines(
        polylines, spacing_m, source=f"grid {r}x{c}, block {block:g} m"
    )


def grid_node(rows: int, cols: int, r: int, c: int) -> int:
    """Index of intersection ``(r, c)`` (row ``r`` at ``y = r·block_m``, column ``c`` at
    ``x = c·block_m``) in :func:`grid_network` of ``rows × cols``: ``c·rows + r``, the one
    numbering of every grid-based file format."""
    if not (0 <= r < rows and 0 <= c < cols):
        raise InvalidInputError("(r, c)", (r, c), f"outside a {rows} x {cols} grid")
    return c * rows + r


def random_network(
    n_junctions: int,
    extent_m: float = 1000.0,
    spacing_m: float = 10.0,
    *,
    extra_road_fraction: float = 0.3,
    seed: int | np.random.Generator = 0,
) -> RoadNetwork:
    """Random planar straight roads between junctions uniform in a square, resampled.

    The roads are the Euclidean minimum spanning tree of the junctions (so the network is
    connected) plus each other edge of their Delaunay triangulation with probability
    ``extra_road_fraction``; a subset of a triangulation, so no two roads cross.

    Parameters
    ----------
    n_junctions
        Number of junctions, ≥ 3.
    extent_m
        Side of the square (m).
    spacing_m
        Node spacing along roads (m).
    extra_road_fraction
        Probability of keeping each non-tree Delaunay edge, in ``[0, 1]``.
    seed
        A seed or a ``numpy.random.Generator``.
    """
    n = checks.count("n_junctions", n_junctions, 3)
    extent = checks.positive("extent_m", extent_m)
    p = float(extra_road_fraction)
    if not 0.0 <= p <= 1.0:
        raise InvalidInputError("extra_road_fraction", extra_road_fraction, "must be in [0, 1]")
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0.0, extent, size=(n, 2))
    tri = Delaunay(xy)
    pairs = np.concatenate([tri.simplices[:, [0, 1]], tri.simplices[:, [1, 2]],
                            tri.simplices[:, [0, 2]]])
    pairs = np.unique(np.sort(pairs, axis=1), axis=0)
    length = np.hypot(*(xy[pairs[:, 0]] - xy[pairs[:, 1]]).T)
    graph = coo_array((length, (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    tree = minimum_spanning_tree(graph).tocoo()
    in_tree = {(int(min(a, b)), int(max(a, b))) for a, b in zip(tree.row, tree.col, strict=True)}
    extra = rng.random(len(pairs)) < p
    keep = [k for k, (a, b) in enumerate(pairs) if (int(a), int(b)) in in_tree or extra[k]]
    polylines = [xy[pairs[k]] for k in keep]
    return network_from_polylines(
        polylines, spacing_m, source=f"random planar roads, {n} junctions, {extent:g} m"
    )
