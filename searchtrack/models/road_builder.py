"""Build a :class:`RoadNetwork` from road polylines, resampled to a uniform node spacing.

The thesis assumes one spacing ``h`` on every edge (§2.2, ``Δx = 10`` m in Table 6.2). Each
polyline (a road between two junctions) of length ``ℓ`` is cut into ``n = ⌈ℓ/h⌉`` pieces of
equal arc length ``ℓ/n ≤ h``, so every edge is at most ``h`` long and, on roads at least ``h``
long, longer than ``h/2``; only roads shorter than ``h`` give shorter edges. A closed polyline
(a loop back to its junction) gets at least 3 pieces, so that it adds no self-loop or double edge.
Polyline ends with equal coordinates become one junction (so duplicate map nodes merge); interior
points never join other polylines. When two junctions are joined by several single-piece roads,
the shortest is kept.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from searchtrack.core.errors import InvalidInputError
from searchtrack.models.projection import LocalProjection
from searchtrack.models.roads import RoadNetwork, validate_spacing

log = logging.getLogger("searchtrack.models.road_builder")

_REL_TOL = 1e-9


def _stack(polylines: Sequence[ArrayLike]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """All polyline points stacked ``(K, 2)``, and the index of the polyline of each point."""
    arrays = []
    for i, raw in enumerate(polylines):
        pts = np.asarray(raw, dtype=np.float64)
        if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 2 or not np.all(np.isfinite(pts)):
            raise InvalidInputError(
                f"polylines[{i}]", raw, "must be finite points of shape (k, 2), k ≥ 2"
            )
        arrays.append(pts)
    if not arrays:
        raise InvalidInputError("polylines", polylines, "needs at least one polyline")
    sizes = np.array([len(a) for a in arrays])
    return np.concatenate(arrays), np.repeat(np.arange(len(arrays)), sizes)


def _drop_repeats(
    pts: NDArray[np.float64], pid: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Remove repeated consecutive points, then polylines left with one point (zero length);
    polyline indices are renumbered ``0..P−1``."""
    keep = np.ones(len(pts), dtype=bool)
    keep[1:] = np.any(pts[1:] != pts[:-1], axis=1) | (pid[1:] != pid[:-1])
    pts, pid = pts[keep], pid[keep]
    counts = np.bincount(pid)
    alive = counts[pid] >= 2
    _, pid = np.unique(pid[alive], return_inverse=True)
    return pts[alive], pid.astype(np.int64)


def network_from_polylines(
    polylines: Sequence[ArrayLike],
    spacing_m: float = 10.0,
    *,
    source: str = "",
    projection: LocalProjection | None = None,
    largest_component: bool = True,
) -> RoadNetwork:
    """A road network whose nodes lie every ``spacing_m`` (or a little less) along the polylines.

    Parameters
    ----------
    polylines
        Roads between junctions, each ``(k, 2)`` planar points (m). A polyline's first and last
        points are junctions, shared with every polyline ending at the same coordinates.
    spacing_m
        Largest node spacing (m) along a road; must be finite and > 0.
    source, projection
        Stored on the network (see :class:`RoadNetwork`).
    largest_component
        Keep only the largest connected component (the default) or every component.

    Raises
    ------
    InvalidInputError
        For a bad ``spacing_m``, a malformed polyline, or no polyline of positive length.
    """
    spacing = validate_spacing(spacing_m)
    pts, pid = _drop_repeats(*_stack(polylines))
    if pts.size == 0:
        raise InvalidInputError("polylines", polylines, "no polyline has positive length")
    n_poly = int(pid[-1]) + 1
    first = np.flatnonzero(np.r_[True, pid[1:] != pid[:-1]])
    last = np.r_[first[1:] - 1, len(pts) - 1]
    junction_xy, junction_of = np.unique(
        np.concatenate([pts[first], pts[last]]), axis=0, return_inverse=True
    )
    head, tail = junction_of[:n_poly], junction_of[n_poly:]

    # arc length along each polyline, and a global abscissa increasing across all of them
    step = np.hypot(*np.diff(pts, axis=0).T) * (pid[1:] == pid[:-1])
    cum = np.r_[0.0, np.cumsum(step)]
    arc = cum - cum[first][pid]
    total = arc[last]
    pieces = np.maximum(1, np.ceil(total / spacing * (1.0 - _REL_TOL)).astype(np.int64))
    pieces = np.where(head == tail, np.maximum(pieces, 3), pieces)
    piece_len = total / pieces
    offset = np.r_[0.0, np.cumsum(total + 1.0)[:-1]]
    abscissa = arc + offset[pid]

    # interior nodes: k·ℓ/n for k = 1..n−1 on each polyline
    inner = pieces - 1
    owner = np.repeat(np.arange(n_poly), inner)
    k = np.arange(owner.size) - np.repeat(np.cumsum(inner) - inner, inner) + 1
    t = offset[owner] + k * piece_len[owner]
    interior = np.column_stack(
        [np.interp(t, abscissa, pts[:, 0]), np.interp(t, abscissa, pts[:, 1])]
    )

    # node chain of each polyline: head junction, its interior nodes, tail junction
    n_junctions = len(junction_xy)
    chain_start = np.r_[0, np.cumsum(pieces + 1)[:-1]]
    chain_end = chain_start + pieces
    chain = np.empty(int((pieces + 1).sum()), dtype=np.int64)
    not_end = np.ones(chain.size, dtype=bool)
    not_end[chain_end] = False
    inside = not_end.copy()
    inside[chain_start] = False
    chain[chain_start], chain[chain_end] = head, tail
    chain[inside] = n_junctions + np.arange(owner.size)
    pair = np.flatnonzero(not_end)  # an edge from every chain position but the last of each
    edges = np.sort(np.column_stack([chain[pair], chain[pair + 1]]), axis=1)
    length = np.repeat(piece_len, pieces)

    # keep the shortest of parallel edges: sort by (u, v, length), take the first of each pair
    order = np.lexsort((length, edges[:, 1], edges[:, 0]))
    edges, length = edges[order], length[order]
    unique = np.r_[True, np.any(edges[1:] != edges[:-1], axis=1)]
    if not np.all(unique):
        log.debug("dropped %d parallel single-piece roads", int((~unique).sum()))
    network = RoadNetwork(
        coords=np.concatenate([junction_xy, interior]),
        edges=edges[unique],
        lengths_m=length[unique],
        source=source,
        spacing_m=spacing,
        projection=projection,
    )
    if largest_component and not network.is_connected:
        full = network
        network = network.largest_component()
        log.info(
            "%s: kept the largest of %d components (%d of %d nodes)",
            source or "network", full.n_components, network.n_nodes, full.n_nodes,
        )
    return network
