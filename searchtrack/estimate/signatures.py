"""Signatures for the EMD of road beliefs (thesis §4.3): truncation and lower bounds.

A diffused tracker or a Gaussian measurement density is nonzero on almost every node, so each is
*truncated*: keep the smallest set of nodes holding at least ``support_mass`` (default 0.999) of
its mass — the heaviest nodes, ties to the lower index — and renormalise it to 1. By the
triangle inequality for W1, the EMD between truncated signatures differs from the full one by at
most ``(1 − support_mass)`` times the farthest road distance from a dropped node to the kept
ones, per side; in practice far less (``benchmarks/association.py`` prints the relative error).

Two lower bounds, both exact for the truncated signatures
``p`` (nodes ``i``) and ``q`` (nodes ``j``) and any optimal flow ``f`` (``Σ f = 1``):

* centroid bound, before any distance is computed: with ``κ`` =
  :attr:`RoadMetric.lower_bound_factor` (road distance ≥ ``κ`` × straight line),
  ``EMD = Σ f_ij d_ij ≥ κ Σ f_ij ‖ψ_i − ψ_j‖ ≥ κ ‖Σ f_ij (ψ_i − ψ_j)‖ = κ ‖ψ̄_p − ψ̄_q‖``
  (triangle inequality for the norm; the marginals of ``f`` are ``p`` and ``q``);
* nearest-support bound, from the distance block: ``Σ_ij f_ij d_ij ≥ Σ_i (Σ_j f_ij) min_j d_ij
  = Σ_i p_i min_j d_ij``, and symmetrically ``Σ_j q_j min_i d_ij``; both are at least the
  distance between the two supports' nearest nodes.

A relative slack of 1e-9 protects against round-off in the bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit
from numpy.typing import ArrayLike

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.models.road_metric import RoadMetric

#: Relative round-off allowance before a lower bound may skip a pair.
SLACK = 1e-9


@dataclass(frozen=True, eq=False)
class Signature:
    """A truncated signature: ascending ``nodes`` and their ``weights`` (> 0, summing to 1)."""

    nodes: IntArray
    weights: FloatArray

    @property
    def size(self) -> int:
        """Number of support nodes."""
        return int(self.nodes.size)


def check_support_mass(support_mass: object) -> float:
    """``support_mass`` as a float in ``(0, 1]``, else :class:`InvalidInputError`."""
    if isinstance(support_mass, bool) or not isinstance(
            support_mass, (int, float, np.integer, np.floating)):
        raise InvalidInputError("support_mass", support_mass, "must be a number in (0, 1]")
    value = float(support_mass)
    if not 0.0 < value <= 1.0:
        raise InvalidInputError("support_mass", support_mass, "must be in (0, 1]")
    return value


def check_gate(gate_m: object, *, inf_ok: bool) -> float:
    """``gate_m`` as a positive float (finite unless ``inf_ok``)."""
    if isinstance(gate_m, bool) or not isinstance(gate_m, (int, float, np.integer, np.floating)):
        raise InvalidInputError("gate_m", gate_m, "must be a positive number of metres")
    value = float(gate_m)
    if math.isnan(value) or value <= 0.0 or (value == math.inf and not inf_ok):
        raise InvalidInputError("gate_m", gate_m, "must be positive" +
                                ("" if inf_ok else " and finite") + " (m)")
    return value


def distributions(name: str, values: ArrayLike, n_nodes: int) -> FloatArray:
    """``values`` as an ``(r, n_nodes)`` array of finite, non-negative rows with positive sums."""
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise InvalidInputError(name, values, "must be a 2-D array of numbers") from None
    if arr.ndim != 2 or arr.shape[1] != n_nodes:
        raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                f"must have shape (rows, {n_nodes}), one column per node")
    if arr.size and arr.flags.c_contiguous != arr.flags.f_contiguous:
        bad, empty_row = _faults(arr, arr.flags.f_contiguous)
        if not bad:  # else the checks below name the fault
            if empty_row >= 0:
                raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                        f"row {empty_row} has no mass")
            return arr
    if not np.all(np.isfinite(arr)):
        raise InvalidInputError(name, f"<array of shape {arr.shape}>", "must be finite")
    if np.any(arr < 0.0):
        raise InvalidInputError(name, f"<array of shape {arr.shape}>", "must be non-negative")
    empty = np.flatnonzero(arr.sum(axis=1) <= 0.0)
    if empty.size:
        raise InvalidInputError(name, f"<array of shape {arr.shape}>",
                                f"row {int(empty[0])} has no mass")
    return arr


@njit(cache=True)
def _faults(a: FloatArray, by_column: bool) -> tuple[bool, int]:
    """Whether ``a`` holds a NaN, infinite or negative entry, and its first row without a
    positive entry (``-1`` if none), in one pass (columns outermost if ``by_column``)."""
    rows, n = a.shape
    positive = np.zeros(rows, dtype=np.bool_)
    bad = False
    if by_column:
        for i in range(n):
            for r in range(rows):
                x = a[r, i]
                bad |= not (0.0 <= x < np.inf)
                positive[r] |= x > 0.0
    else:
        for r in range(rows):
            row = a[r]
            some = False
            for i in range(n):
                x = row[i]
                bad |= not (0.0 <= x < np.inf)
                some |= x > 0.0
            positive[r] = some
    for r in range(rows):
        if not positive[r]:
            return bad, r
    return bad, -1


def truncate_signature(weights: ArrayLike, support_mass: float = 0.999) -> Signature:
    """The smallest node set holding ≥ ``support_mass`` of ``weights``' mass, renormalised.

    Nodes are taken heaviest first (ties: lower index first); ``support_mass = 1`` keeps every
    node of positive weight. Only nodes heavier than ``(1 − support_mass) · total / n`` are
    sorted: the lighter ones hold at most ``(1 − support_mass) · total`` together, so they are
    exactly the lightest nodes and never needed.

    Raises
    ------
    InvalidInputError
        ``weights`` not a non-empty 1-D array of finite non-negative numbers with a positive
        sum, or ``support_mass`` outside ``(0, 1]``.
    """
    mass = check_support_mass(support_mass)
    w = np.asarray(weights, dtype=np.float64)
    if w.ndim != 1 or w.size == 0:
        raise InvalidInputError("weights", weights, "must be a non-empty 1-D array")
    return truncate(distributions("weights", w[None, :], w.size)[0], mass)


def truncate(w: FloatArray, mass: float) -> Signature:
    """:func:`truncate_signature` for a validated row ``w`` and ``mass``."""
    if mass < 1.0:
        return truncate_rows(w[None, :], mass)[0]
    return _signature(w, np.flatnonzero(w > 0.0).astype(np.int64))


@lru_cache(maxsize=8)
def _pairwise_program(n: int) -> tuple[IntArray, IntArray, IntArray]:
    """NumPy's pairwise summation of ``n`` numbers as leaves (``start``, ``length``: blocks of
    at most 128, summed with eight accumulators) and a postfix program over them (``k ≥ 0``:
    push leaf ``k``'s sum; ``-1``: replace the top two by their sum, left + right)."""
    starts: list[int] = []
    lengths: list[int] = []
    ops: list[int] = []

    def split(start: int, length: int) -> None:
        if length <= 128:
            ops.append(len(starts))
            starts.append(start)
            lengths.append(length)
            return
        half = length // 2
        half -= half % 8
        split(start, half)
        split(start + half, length - half)
        ops.append(-1)

    split(0, n)
    return (np.array(starts, dtype=np.int64), np.array(lengths, dtype=np.int64),
            np.array(ops, dtype=np.int64))


@njit(cache=True)
def _row_sums(a: FloatArray, starts: IntArray, lengths: IntArray, ops: IntArray) -> FloatArray:
    """Each row's sum of ``a`` exactly as NumPy's pairwise ``a[r].sum()``, columns outermost."""
    rows = a.shape[0]
    leaves = np.empty((starts.shape[0], rows), dtype=np.float64)
    acc = np.empty((8, rows), dtype=np.float64)
    for leaf in range(starts.shape[0]):
        s, m = starts[leaf], lengths[leaf]
        res = leaves[leaf]
        if m < 8:
            res[:] = -0.0
            for i in range(s, s + m):
                for r in range(rows):
                    res[r] += a[r, i]
            continue
        for j in range(8):
            for r in range(rows):
                acc[j, r] = a[r, s + j]
        i = s + 8
        while i < s + m - m % 8:
            for j in range(8):
                for r in range(rows):
                    acc[j, r] += a[r, i + j]
            i += 8
        for r in range(rows):
            res[r] = ((acc[0, r] + acc[1, r]) + (acc[2, r] + acc[3, r])) + (
                (acc[4, r] + acc[5, r]) + (acc[6, r] + acc[7, r]))
        for i in range(s + m - m % 8, s + m):
            for r in range(rows):
                res[r] += a[r, i]
    stack = np.empty((ops.shape[0], rows), dtype=np.float64)
    top = 0
    for op in ops:
        if op >= 0:
            stack[top] = leaves[op]
            top += 1
        else:
            top -= 1
            stack[top - 1] += stack[top]
    sums: FloatArray = stack[0].copy()
    return sums


_ROW_CAP = 4096  # candidates a row holds before its count decides where they go


@njit(cache=True)
def _candidates(a: FloatArray, floor: FloatArray, by_column: bool, cap: int,
                first: IntArray | None = None) -> tuple[IntArray, IntArray]:
    """Each row's entries above its ``floor`` (ascending indices), concatenated, and the rows'
    offsets in it, in one pass: up to ``cap`` a row into a buffer, or, given the offsets
    ``first``, straight into place. Offsets negated mean a row had more than ``cap``."""
    rows, n = a.shape
    count = np.zeros(rows, dtype=np.int64)
    placed = first is not None
    start = first if first is not None else np.zeros(rows + 1, dtype=np.int64)
    out = np.empty(start[rows] if placed else rows * cap, dtype=np.int64)
    for r in range(rows):
        if not placed:
            start[r] = r * cap
    if by_column:
        for i in range(n):  # indices ascending within a row
            for r in range(rows):
                if a[r, i] > floor[r]:
                    k = count[r]
                    if placed or k < cap:
                        out[start[r] + k] = i
                    count[r] = k + 1
    else:
        for r in range(rows):
            row, cut, k, base = a[r], floor[r], 0, start[r]
            for i in range(n):
                if row[i] > cut:
                    if placed or k < cap:
                        out[base + k] = i
                    k += 1
            count[r] = k
    if placed:
        return out, start
    offsets = np.zeros(rows + 1, dtype=np.int64)
    for r in range(rows):
        offsets[r + 1] = offsets[r] + count[r]
    if count.max() > cap:
        return out[:0], -offsets
    cand = np.empty(offsets[rows], dtype=np.int64)
    for r in range(rows):
        cand[offsets[r]:offsets[r + 1]] = out[r * cap:r * cap + count[r]]
    return cand, offsets


@njit(cache=True)
def _heaviest(a: FloatArray, total: FloatArray, mass: float,
              by_column: bool) -> tuple[IntArray, IntArray]:
    """Every row's :func:`truncate` support (ascending nodes) given the row totals,
    concatenated, and the offsets of the rows in it: one pass over ``a`` (two if a row has more
    than ``_ROW_CAP`` candidates; columns outermost if ``by_column``, for a Fortran-ordered
    ``a``), then a sort of each row's candidates."""
    rows, n = a.shape
    floor = np.empty(rows, dtype=np.float64)
    for r in range(rows):
        floor[r] = (1.0 - mass) * total[r] / n
    cand, first = _candidates(a, floor, by_column, min(n, _ROW_CAP))
    if first[rows] < 0:  # a row overflowed its buffer: place every row's by the counts
        first = -first
        cand = _candidates(a, floor, by_column, 0, first)[0]
    nodes = np.empty(cand.shape[0], dtype=np.int64)
    offsets = np.zeros(rows + 1, dtype=np.int64)
    for r in range(rows):
        mine = cand[first[r]:first[r + 1]]
        neg = np.empty(mine.shape[0], dtype=np.float64)
        for k in range(mine.shape[0]):
            neg[k] = -a[r, mine[k]]
        order = np.argsort(neg, kind="mergesort")  # stable: ties keep ascending indices
        target = mass * total[r]
        acc = 0.0
        keep = mine.shape[0]
        for k in range(mine.shape[0]):
            acc += a[r, mine[order[k]]]
            if acc >= target:
                keep = k + 1
                break
        nodes[offsets[r]:offsets[r] + keep] = np.sort(mine[order[:keep]])
        offsets[r + 1] = offsets[r] + keep
    return nodes[:offsets[rows]].copy(), offsets


def truncate_rows(arr: FloatArray, mass: float) -> list[Signature]:
    """:func:`truncate` of every row of a validated ``(r, n)`` array, in one sweep of it.

    Row totals are NumPy's pairwise sums of the rows, as ``row.sum()`` gives them (for a
    Fortran-ordered array, a transposed bank, by :func:`_row_sums` in memory order).
    """
    if mass >= 1.0 or arr.shape[0] == 0 or arr.shape[1] == 0:
        return [truncate(row, mass) for row in arr]
    by_column = bool(arr.flags.f_contiguous and not arr.flags.c_contiguous)
    if by_column:
        total = _row_sums(arr, *_pairwise_program(arr.shape[1]))
    else:
        total = np.array([row.sum() for row in arr]) if not arr.flags.c_contiguous else (
            arr.sum(axis=1))
    nodes, offsets = _heaviest(arr, total, mass, by_column)
    return [_signature(arr[r], nodes[offsets[r]:offsets[r + 1]]) for r in range(arr.shape[0])]


def _signature(w: FloatArray, nodes: IntArray) -> Signature:
    kept = w[nodes] / w[nodes].sum()
    nodes = nodes.copy()
    nodes.setflags(write=False)
    kept.setflags(write=False)
    return Signature(nodes, kept)


def warm_up() -> None:
    """Compile (or load from numba's cache) the truncation kernels, for C- and Fortran-ordered
    rows and a row past the candidate buffer."""
    w = np.array([[0.5, 0.25, 0.25], [0.0, 1.0, 0.0]])
    for arr in (w, np.asfortranarray(w)):
        distributions("warm-up", arr, 3)
        truncate_rows(arr, 0.9)
    _candidates(w, np.zeros(2), False, 0, np.array([0, 3, 4]))
    _candidates(np.asfortranarray(w), np.zeros(2), True, 0, np.array([0, 3, 4]))


def centroid_bound(metric: RoadMetric, left: list[Signature],
                   right: list[Signature]) -> FloatArray:
    """``(len(left), len(right))`` lower bounds ``κ ‖ψ̄_p − ψ̄_q‖`` on the EMD (m)."""
    xy = metric.network.coords

    def centroids(sigs: list[Signature]) -> FloatArray:
        return np.array([s.weights @ xy[s.nodes] for s in sigs]).reshape(len(sigs), 2)

    a, b = centroids(left), centroids(right)
    gap = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return np.asarray(metric.lower_bound_factor * gap, dtype=np.float64)


def nearest_support_bound(cost: FloatArray, p: FloatArray, q: FloatArray) -> float:
    """``max(Σ_i p_i min_j d_ij, Σ_j q_j min_i d_ij)`` ≤ EMD (``inf`` if some mass is cut off)."""
    return float(max(p @ cost.min(axis=1), q @ cost.min(axis=0)))
