"""Numba kernels that resample the road particle clouds in place (see
:mod:`searchtrack.estimate.road_pf`): low-variance resampling of a cloud, of a cloud joined with
draws (jumps, draws near a detection), and the KLD-sampling count of the particles kept
(:class:`~searchtrack.estimate.road_resampling.KLDSampling`).

A cloud of capacity ``N`` holds ``count[f] ≤ N`` particles in its first columns, each of weight
``1/count[f]`` after a resampling; the columns beyond weigh 0 and keep stale but valid road
positions. The NumPy reference of the choice is
:func:`~searchtrack.estimate.road_resampling.systematic_indices`.

KLD-sampling: the cap's systematic sample is drawn, the bins it fills are counted (road bin
``first_bin[e] + ⌊s / bin_m⌋`` of directed edge ``e``, clipped to the edge's last, times the
speed bins ``⌊v / speed_bin⌋`` when ``seen`` holds several per road bin), and the cloud keeps
``table[k]`` particles, drawn systematically from the same weights with the same offset.
An empty ``table`` keeps the cap (fixed counts).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from searchtrack.core.types import BoolArray, FloatArray, IntArray


@njit(cache=True)
def _pick(uw: FloatArray, m: int, total: float, u: float, n_out: int, idx: IntArray) -> None:
    """``idx[:n_out]``: output ``j`` is the first of the ``m`` weights ``uw`` whose cumulative
    share of ``total`` exceeds ``(u + j) / n_out`` (the last one if round-off leaves none)."""
    k = 0
    c = uw[0] / total
    for j in range(n_out):
        target = (u + j) / n_out
        while c <= target and k < m - 1:
            k += 1
            c += uw[k] / total
        idx[j] = k


@njit(cache=True)
def _bin(e: int, s: float, v: float, first_bin: IntArray, bin_m: float, speed_bin: float,
         n_speed: int) -> int:
    """The bin of a particle: its road bin, times ``n_speed`` speed bins of ``speed_bin``."""
    last = int(first_bin[e + 1] - first_bin[e] - 1)
    b = int(first_bin[e]) + min(max(int(s / bin_m), 0), last)
    if n_speed > 1:
        b = b * n_speed + min(max(int(v / speed_bin), 0), n_speed - 1)
    return b


@njit(cache=True)
def _bins_filled(ue: IntArray, us: FloatArray, uv: FloatArray, idx: IntArray, n: int,
                 first_bin: IntArray, bin_m: float, speed_bin: float, seen: BoolArray) -> int:
    """The bins the chosen particles ``idx[:n]`` of ``(ue, us, uv)`` fill; ``seen`` (all
    false, one per bin: ``n_speed`` = its size over the road bins) is left all false."""
    n_speed = seen.size // first_bin[first_bin.size - 1]
    k = 0
    for j in range(n):
        i = idx[j]
        b = _bin(ue[i], us[i], uv[i], first_bin, bin_m, speed_bin, n_speed)
        if not seen[b]:
            seen[b] = True
            k += 1
    for j in range(n):
        i = idx[j]
        seen[_bin(ue[i], us[i], uv[i], first_bin, bin_m, speed_bin, n_speed)] = False
    return k


@njit(cache=True)
def _store_union(edge: IntArray, s: FloatArray, v: FloatArray, w: FloatArray, count: IntArray,
                 r: int, ue: IntArray, us: FloatArray, uv: FloatArray, uw: FloatArray, m: int,
                 total: float, u: float, idx: IntArray, first_bin: IntArray, bin_m: float,
                 speed_bin: float, seen: BoolArray, table: IntArray) -> None:
    """Row ``r`` becomes the systematic resampling of the union ``u*[:m]`` (weights ``uw``
    summing to ``total``), ``table[k]`` particles of it (the cap with an empty table)."""
    cap = edge.shape[1]
    _pick(uw, m, total, u, cap, idx)
    n_out = cap
    if table.size:
        n_out = table[_bins_filled(ue, us, uv, idx, cap, first_bin, bin_m, speed_bin, seen)]
        if n_out < cap:
            _pick(uw, m, total, u, n_out, idx)
    for j in range(n_out):
        edge[r, j] = ue[idx[j]]
        s[r, j] = us[idx[j]]
        v[r, j] = uv[idx[j]]
        w[r, j] = 1.0 / n_out
    for j in range(n_out, cap):
        w[r, j] = 0.0
    count[r] = n_out


@njit(cache=True)
def _load_row(edge: IntArray, s: FloatArray, v: FloatArray, w: FloatArray, r: int, m: int,
              mass: float, ue: IntArray, us: FloatArray, uv: FloatArray, uw: FloatArray) -> float:
    """The first ``m`` particles of row ``r`` into the union's first slots, weighing
    ``mass · w``; their total weight."""
    total = 0.0
    for n in range(m):
        ue[n] = edge[r, n]
        us[n] = s[r, n]
        uv[n] = v[r, n]
        uw[n] = w[r, n] * mass
        total += uw[n]
    return total


@njit(cache=True)
def resample_rows(edge: IntArray, s: FloatArray, v: FloatArray, w: FloatArray, count: IntArray,
                  rows: IntArray, u: FloatArray, first_bin: IntArray, bin_m: float,
                  speed_bin: float, seen: BoolArray, table: IntArray) -> None:
    """Low-variance resampling in place of the listed rows, row ``rows[i]`` (its ``count``
    particles) with offset ``u[i]`` in ``[0, 1)``, to ``table[k]`` particles (module
    docstring; the cap ``N`` with an empty table), each of weight ``1/count``."""
    cap = edge.shape[1]
    ue = np.empty(cap, dtype=edge.dtype)
    us = np.empty(cap)
    uv = np.empty(cap)
    uw = np.empty(cap)
    idx = np.empty(cap, dtype=np.int64)
    for i in range(rows.size):
        r = rows[i]
        m = count[r]
        total = _load_row(edge, s, v, w, r, m, 1.0, ue, us, uv, uw)
        _store_union(edge, s, v, w, count, r, ue, us, uv, uw, m, total, u[i], idx, first_bin,
                     bin_m, speed_bin, seen, table)


@njit(cache=True)
def join_rows(edge: IntArray, s: FloatArray, v: FloatArray, w: FloatArray, count: IntArray,
              rows: IntArray, mass: FloatArray, add_edge: IntArray, add_s: FloatArray,
              add_v: FloatArray, add_w: FloatArray, u: FloatArray, first_bin: IntArray,
              bin_m: float, speed_bin: float, seen: BoolArray, table: IntArray) -> None:
    """Join draws to the listed rows and resample each union as :func:`resample_rows` does,
    in place.

    Row ``rows[i]``'s particles weigh ``mass[i] · w`` and its draws ``add_*[i]`` ``(K,)`` weigh
    ``add_w[i]``; output ``j`` copies the first particle of the union (the row's, then its
    draws) whose cumulative weight exceeds ``(u[i] + j) / n`` of the total. A row whose union
    weighs nothing is left as it is.
    """
    cap, k_count = edge.shape[1], add_edge.shape[1]
    ue = np.empty(cap + k_count, dtype=edge.dtype)
    us = np.empty(cap + k_count)
    uv = np.empty(cap + k_count)
    uw = np.empty(cap + k_count)
    idx = np.empty(cap, dtype=np.int64)
    for i in range(rows.size):
        r = rows[i]
        m = count[r]
        total = _load_row(edge, s, v, w, r, m, mass[i], ue, us, uv, uw)
        for k in range(k_count):
            ue[m + k] = add_edge[i, k]
            us[m + k] = add_s[i, k]
            uv[m + k] = add_v[i, k]
            uw[m + k] = add_w[i, k]
            total += add_w[i, k]
        if not total > 0.0:
            continue
        _store_union(edge, s, v, w, count, r, ue, us, uv, uw, m + k_count, total, u[i], idx,
                     first_bin, bin_m, speed_bin, seen, table)
