"""The numba passes behind :mod:`.signatures`: validation, row totals and truncation of a
``(rows, n)`` array of road distributions in one or two sweeps over memory.

A scan's tracker bank and measurement densities are each ``rows × n_nodes`` doubles (80 MB at
100 rows of a 10⁵-node map), so these passes are bound by memory bandwidth. For C-ordered arrays
every pass runs its rows in parallel (``prange``); a Fortran-ordered array (a transposed bank)
is swept columns outermost, in memory order, by one thread. Each row's total is NumPy's pairwise
sum of the row (:func:`pairwise_program`), so a row's truncation here equals that of the row
alone.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numba import njit, prange

from searchtrack.core.types import FloatArray, IntArray

ROW_CAP = 4096  # candidates a row holds before its count decides where they go


_PARTS = 16  # column chunks of a Fortran-ordered sweep (numba's threads share them out)


@njit(cache=True)
def _chunks(n: int) -> IntArray:
    """Bounds of the contiguous, ascending column chunks a Fortran-ordered sweep splits ``n``
    columns into."""
    count = max(1, min(n, _PARTS))
    return np.array([n * c // count for c in range(count + 1)], dtype=np.int64)


@njit(cache=True, parallel=True)
def faults(a: FloatArray, by_column: bool) -> tuple[np.bool_, int]:
    """Whether ``a`` holds a NaN, infinite or negative entry, and its first row without a
    positive entry (``-1`` if none), in one pass (columns outermost if ``by_column``)."""
    rows, n = a.shape
    if by_column:
        bounds = _chunks(n)
        parts = bounds.shape[0] - 1
        positive = np.zeros((parts, rows), dtype=np.bool_)
        bad_part = np.zeros(parts, dtype=np.bool_)
        for c in prange(parts):
            bad = False
            mine = positive[c]
            for i in range(bounds[c], bounds[c + 1]):
                for r in range(rows):
                    x = a[r, i]
                    bad |= not (0.0 <= x < np.inf)
                    mine[r] |= x > 0.0
            bad_part[c] = bad
        any_bad = bad_part.any()
        for r in range(rows):
            if not positive[:, r].any():
                return any_bad, r
        return any_bad, -1
    some = np.zeros(rows, dtype=np.bool_)
    bad_row = np.zeros(rows, dtype=np.bool_)
    for r in prange(rows):
        hit, wrong = False, False
        for i in range(n):
            x = a[r, i]
            wrong |= not (0.0 <= x < np.inf)
            hit |= x > 0.0
        some[r] = hit
        bad_row[r] = wrong
    any_bad = bad_row.any()
    for r in range(rows):
        if not some[r]:
            return any_bad, r
    return any_bad, -1


@lru_cache(maxsize=8)
def pairwise_program(n: int) -> tuple[IntArray, IntArray, IntArray]:
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


@njit(cache=True, parallel=True)
def row_sums_by_column(a: FloatArray, starts: IntArray, lengths: IntArray,
                       ops: IntArray) -> FloatArray:
    """Each row's sum of ``a`` exactly as NumPy's pairwise ``a[r].sum()``, columns outermost."""
    rows = a.shape[0]
    leaves = np.empty((starts.shape[0], rows), dtype=np.float64)
    for leaf in prange(starts.shape[0]):
        acc = np.empty((8, rows), dtype=np.float64)
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


@njit(cache=True, parallel=True)
def row_sums(a: FloatArray, starts: IntArray, lengths: IntArray, ops: IntArray) -> FloatArray:
    """:func:`row_sums_by_column` of a C-ordered ``a``, rows in parallel."""
    rows = a.shape[0]
    sums = np.empty(rows, dtype=np.float64)
    for r in prange(rows):
        row = a[r]
        stack = np.empty(ops.shape[0], dtype=np.float64)
        acc = np.empty(8, dtype=np.float64)
        top = 0
        for op in ops:
            if op < 0:
                top -= 1
                stack[top - 1] += stack[top]
                continue
            s, m = starts[op], lengths[op]
            if m < 8:
                res = -0.0
                for i in range(s, s + m):
                    res += row[i]
            else:
                for j in range(8):
                    acc[j] = row[s + j]
                i = s + 8
                while i < s + m - m % 8:
                    for j in range(8):
                        acc[j] += row[i + j]
                    i += 8
                res = ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (
                    acc[6] + acc[7]))
                for i in range(s + m - m % 8, s + m):
                    res += row[i]
            stack[top] = res
            top += 1
        sums[r] = stack[0]
    return sums


@njit(cache=True, parallel=True)
def candidates(a: FloatArray, floor: FloatArray, by_column: bool, cap: int,
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
        for r in prange(rows):
            cut, k, base = floor[r], 0, start[r]
            for i in range(n):
                if a[r, i] > cut:
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


@njit(cache=True, parallel=True)
def heaviest(a: FloatArray, total: FloatArray, mass: float,
             by_column: bool) -> tuple[IntArray, IntArray]:
    """Every row's :func:`~.signatures.truncate` support (ascending nodes) given the row totals,
    concatenated, and the offsets of the rows in it: one pass over ``a`` (two if a row has more
    than ``ROW_CAP`` candidates; columns outermost if ``by_column``, for a Fortran-ordered
    ``a``), then a sort of each row's candidates."""
    rows, n = a.shape
    floor = np.empty(rows, dtype=np.float64)
    for r in range(rows):
        floor[r] = (1.0 - mass) * total[r] / n
    cand, first = candidates(a, floor, by_column, min(n, ROW_CAP))
    if first[rows] < 0:  # a row overflowed its buffer: place every row's by the counts
        first = -first
        cand = candidates(a, floor, by_column, 0, first)[0]
    kept = np.empty(cand.shape[0], dtype=np.int64)  # row r's support at first[r]:
    keep = np.zeros(rows, dtype=np.int64)
    for r in prange(rows):
        mine = cand[first[r]:first[r + 1]]
        neg = np.empty(mine.shape[0], dtype=np.float64)
        for k in range(mine.shape[0]):
            neg[k] = -a[r, mine[k]]
        order = np.argsort(neg, kind="mergesort")  # stable: ties keep ascending indices
        target = mass * total[r]
        acc = 0.0
        count = mine.shape[0]
        for k in range(mine.shape[0]):
            acc += a[r, mine[order[k]]]
            if acc >= target:
                count = k + 1
                break
        kept[first[r]:first[r] + count] = np.sort(mine[order[:count]])
        keep[r] = count
    offsets = np.zeros(rows + 1, dtype=np.int64)
    for r in range(rows):
        offsets[r + 1] = offsets[r] + keep[r]
    nodes = np.empty(offsets[rows], dtype=np.int64)
    for r in range(rows):
        nodes[offsets[r]:offsets[r + 1]] = kept[first[r]:first[r] + keep[r]]
    return nodes, offsets
