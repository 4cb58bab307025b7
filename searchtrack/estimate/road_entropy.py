"""Entropy and MAP position of weighted particle clouds on road bins (Moore et al. 2021, Eq. 19,
Eq. 40).

Each directed edge is cut into bins of ``bin_m`` metres from its tail (the last bin of an edge
may be shorter), so a two-way road is binned once per direction. The entropy of a cloud is
``−Σ_b p_b log p_b`` in nats over the bin masses ``p_b`` (the weights of the particles in bin
``b``, normalized per cloud): Eq. 19 with the minus sign the print lacks, in nats because the
paper's worked example (2.89 nats ↔ 19 m²) only holds in nats with 1 m bins. The authors plot
it with 5 m bins (the default here) and compare with the bound on 1 m bins.

The "combined entropy" of the paper's figures pools the ``M`` targets of one hypothesis: the
histogram of all ``M·N`` particles with mass ``w / M`` each.

Every function takes a batch of clouds ``(B, N)`` (targets, filters or histories × targets) and
bins them in one ``np.bincount`` with per-row offsets, or, when ``B × bins`` would be large
(long maps), by sorting the ``(row, bin)`` keys.

The MAP position of a cloud is the centre of its densest bin (the midpoint of the bin's arc on
its directed edge); ties go to the lowest bin index.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from searchtrack.core import checks
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.road_particles import DirectedRoads

#: Use the dense ``(B, bins)`` histogram when it has at most this many cells per particle.
_DENSE_CELLS_PER_PARTICLE = 4


@dataclass(frozen=True, eq=False)
class RoadBins:
    """The directed edges of ``roads`` cut into bins of ``bin_m`` metres.

    Parameters
    ----------
    roads
        The directed road network.
    bin_m
        Bin length (m), > 0: 5 for the paper's plots, 1 for comparisons with its bound.

    Attributes
    ----------
    first_bin
        ``(2m + 1,)``: the bins of directed edge ``d`` are ``first_bin[d] .. first_bin[d+1] − 1``.
    """

    roads: DirectedRoads
    bin_m: float = 5.0
    first_bin: IntArray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "bin_m", checks.positive("bin_m", self.bin_m))
        per_edge = np.maximum(np.ceil(self.roads.length / self.bin_m - 1e-9), 1).astype(np.int64)
        first = np.zeros(per_edge.size + 1, dtype=np.int64)
        np.cumsum(per_edge, out=first[1:])
        first.setflags(write=False)
        object.__setattr__(self, "first_bin", first)

    @property
    def n_bins(self) -> int:
        """Total number of bins."""
        return int(self.first_bin[-1])

    def index(self, edge: IntArray, s: FloatArray) -> IntArray:
        """Bin of each position ``(edge, s)`` (any shape)."""
        k = (np.asarray(s) / self.bin_m).astype(np.int64)
        last = self.first_bin[edge + 1] - self.first_bin[edge] - 1
        return np.asarray(self.first_bin[edge] + np.clip(k, 0, last), dtype=np.int64)

    def centre(self, bins: IntArray) -> tuple[IntArray, FloatArray]:
        """``(edge, s)`` of the midpoint of each bin's arc."""
        b = np.asarray(bins, dtype=np.int64)
        edge = np.searchsorted(self.first_bin, b, side="right") - 1
        k = b - self.first_bin[edge]
        start = k * self.bin_m
        end = np.minimum(start + self.bin_m, self.roads.length[edge])
        return edge.astype(np.int64), 0.5 * (start + end)


def _checked(bins: RoadBins, edge: IntArray, s: FloatArray,
             w: FloatArray) -> tuple[IntArray, FloatArray]:
    """Bin indices and row-normalized weights of a ``(B, N)`` batch, checked."""
    e = np.asarray(edge)
    if e.ndim != 2:
        raise InvalidInputError("edge", e.shape, "must be a (B, N) array")
    ww = np.asarray(w, dtype=np.float64)
    if ww.shape != e.shape:
        raise InvalidInputError("w", ww.shape, f"must have the shape of edge {e.shape}")
    bins.roads.check_positions(e, np.asarray(s, dtype=np.float64))
    totals = ww.sum(axis=1, keepdims=True)
    if not np.all(np.isfinite(ww)) or np.any(ww < 0.0) or np.any(totals <= 0.0):
        raise InvalidInputError("w", ww.shape, "must be finite, ≥ 0, with positive row sums")
    return bins.index(e, s), ww / totals


def _dense(bins: RoadBins, idx: IntArray, p: FloatArray) -> FloatArray | None:
    """The ``(B, bins)`` histogram of a batch, or None when it would be too large."""
    rows = idx.shape[0]
    if rows * bins.n_bins > _DENSE_CELLS_PER_PARTICLE * idx.size:
        return None
    key = (idx + np.arange(rows)[:, None] * bins.n_bins).ravel()
    return np.asarray(np.bincount(key, weights=p.ravel(), minlength=rows * bins.n_bins),
                      dtype=np.float64)


def _masses(bins: RoadBins, idx: IntArray,
            p: FloatArray) -> tuple[IntArray, IntArray, FloatArray]:
    """The occupied ``(row, bin, mass)`` triples of a batch, sorted by row then bin."""
    rows = idx.shape[0]
    dense = _dense(bins, idx, p)
    if dense is not None:
        occupied = np.flatnonzero(dense > 0.0).astype(np.int64)
        return occupied // bins.n_bins, occupied % bins.n_bins, np.asarray(dense[occupied],
                                                                           dtype=np.float64)
    key = (idx + np.arange(rows, dtype=np.int64)[:, None] * bins.n_bins).ravel()
    order = np.argsort(key, kind="stable")
    sk = key[order]
    starts = np.flatnonzero(np.r_[True, sk[1:] != sk[:-1]])
    mass = np.add.reduceat(p.ravel()[order], starts)
    keys = sk[starts]
    keep = mass > 0.0
    return keys[keep] // bins.n_bins, keys[keep] % bins.n_bins, mass[keep]


def entropy(bins: RoadBins, edge: IntArray, s: FloatArray, w: FloatArray) -> FloatArray:
    """``(B,)`` entropy (nats) of each cloud of a ``(B, N)`` batch on road bins (Eq. 19).

    Weights are normalized per row; a cloud in a single bin has entropy 0.

    Raises
    ------
    InvalidInputError
        Shapes differ, positions are off the roads, or a row of weights is not positive.
    """
    return _entropy(bins, *_checked(bins, edge, s, w))


def _entropy(bins: RoadBins, idx: IntArray, p: FloatArray) -> FloatArray:
    row, _, mass = _masses(bins, idx, p)
    h = np.bincount(row, weights=-mass * np.log(mass), minlength=idx.shape[0])
    # A cloud in one bin has mass 1 − ε there: −(1−ε)·log(1−ε) rounds to ±1e-16; entropy ≥ 0.
    return np.maximum(np.asarray(h, dtype=np.float64), 0.0)


def combined_entropy(bins: RoadBins, edge: IntArray, s: FloatArray, w: FloatArray) -> float:
    """Entropy (nats) of the pooled histogram of all the clouds of a ``(M, N)`` batch, each
    target's mass ``1/M`` (the paper's "combined entropy", Fig. 10–11)."""
    return _combined(bins, *_checked(bins, edge, s, w))


def _combined(bins: RoadBins, idx: IntArray, p: FloatArray) -> float:
    _, _, mass = _masses(bins, idx.reshape(1, -1), p.reshape(1, -1) / idx.shape[0])
    return max(0.0, float(-(mass * np.log(mass)).sum()))


def map_bins(bins: RoadBins, edge: IntArray, s: FloatArray, w: FloatArray) -> IntArray:
    """``(B,)`` densest bin of each cloud of a ``(B, N)`` batch (lowest index on ties)."""
    return _map_bins(bins, *_checked(bins, edge, s, w))


def _map_bins(bins: RoadBins, idx: IntArray, p: FloatArray) -> IntArray:
    dense = _dense(bins, idx, p)
    if dense is not None:
        return np.asarray(dense.reshape(idx.shape[0], -1).argmax(axis=1), dtype=np.int64)
    row, b, mass = _masses(bins, idx, p)
    order = np.lexsort((b, -mass, row))
    first = np.r_[True, row[order][1:] != row[order][:-1]]
    return np.asarray(b[order][first], dtype=np.int64)


def map_positions(bins: RoadBins, edge: IntArray, s: FloatArray, w: FloatArray) -> FloatArray:
    """``(B, 2)`` planar MAP position of each cloud: the centre of its densest bin."""
    return _points(bins, map_bins(bins, edge, s, w))


def _points(bins: RoadBins, best: IntArray) -> FloatArray:
    e, c = bins.centre(best)
    return bins.roads.point(e, c)


def summary(bins: RoadBins, edge: IntArray, s: FloatArray,
            w: FloatArray) -> tuple[FloatArray, float, FloatArray]:
    """:func:`entropy`, :func:`combined_entropy` and :func:`map_positions` of one ``(M, N)``
    batch, checked and binned once (what a tracker reports every scan)."""
    idx, p = _checked(bins, edge, s, w)
    return (_entropy(bins, idx, p), _combined(bins, idx, p),
            _points(bins, _map_bins(bins, idx, p)))
