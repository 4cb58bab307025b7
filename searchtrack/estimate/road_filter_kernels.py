"""Numba kernels of the road particle filters (see :mod:`searchtrack.estimate.road_pf`).

Particle clouds are ``(F, N)`` arrays: directed edge ``edge``, arc length ``s`` (m) and
normalized weights ``w`` (each row sums to 1). A particle's planar point ``G(x)`` is
``tail_xy[e] + s · step_xy[e]`` (:class:`~searchtrack.models.road_particles.DirectedRoads`).
Random numbers are drawn by the caller's ``numpy.random.Generator`` and passed in. The NumPy
references are :meth:`~searchtrack.models.disc_sensor.DiscSensor.likelihood`,
:meth:`~searchtrack.models.disc_sensor.DiscSensor.miss_likelihood`,
:func:`~searchtrack.estimate.road_resampling.systematic_indices` and
:func:`~searchtrack.estimate.road_jumps.near_detection`.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from searchtrack.core.types import FloatArray, IntArray

#: Beyond this exponent the Gaussian term of Eq. 10 is below 1e-304 of its peak: skip ``exp``.
_MAX_EXPONENT = 700.0


@njit(cache=True)
def detection_likelihood(edge: IntArray, s: FloatArray, w: FloatArray, tail_xy: FloatArray,
                         step_xy: FloatArray, yx: float, yy: float, gain: float,
                         inv_two_var: float, floor: float, lik: FloatArray,
                         sums: FloatArray) -> None:
    """Eq. 10 for every particle into ``lik`` ``(F, N)``, and ``sums[f] = Σ_n w p(y | x)``
    (Eq. 16) per row: ``p = gain · exp(−‖G(x) − y‖² · inv_two_var) + floor``."""
    f_count, n_count = edge.shape
    for f in range(f_count):
        acc = 0.0
        for n in range(n_count):
            e = edge[f, n]
            dx = tail_xy[e, 0] + s[f, n] * step_xy[e, 0] - yx
            dy = tail_xy[e, 1] + s[f, n] * step_xy[e, 1] - yy
            q = (dx * dx + dy * dy) * inv_two_var
            p = floor
            if q < _MAX_EXPONENT:
                p += gain * math.exp(-q)
            lik[f, n] = p
            acc += w[f, n] * p
        sums[f] = acc


@njit(cache=True)
def weigh_rows(w: FloatArray, lik: FloatArray, rows: IntArray) -> None:
    """Bayes' rule (Eq. 4, Eq. 6) on the listed rows: ``w ← w · lik``, normalized; a row whose
    product is all zero is left unchanged (the measurement cannot tell its particles apart)."""
    n_count = w.shape[1]
    for r in rows:
        acc = 0.0
        for n in range(n_count):
            acc += w[r, n] * lik[r, n]
        if acc > 0.0:
            for n in range(n_count):
                w[r, n] = w[r, n] * lik[r, n] / acc


@njit(cache=True)
def miss_update(edge: IntArray, s: FloatArray, w: FloatArray, rows: IntArray,
                tail_xy: FloatArray, step_xy: FloatArray, cx: float, cy: float, r2: float,
                p_fn: float, sums: FloatArray, touched: np.ndarray) -> None:
    """Negative information (Eq. 11 as intended) on the listed rows: weights of particles within
    ``√r2`` of ``(cx, cy)`` are multiplied by ``p_fn``, then the row is normalized.

    ``sums[i]`` gets the row's no-detection likelihood ``Σ_n w p(z | x)`` (before normalizing)
    and ``touched[i]`` whether any weight changed; a row whose likelihood is 0 is left as is.
    """
    n_count = edge.shape[1]
    for i in range(rows.size):
        r = rows[i]
        acc = 0.0
        hit = False
        for n in range(n_count):
            e = edge[r, n]
            dx = tail_xy[e, 0] + s[r, n] * step_xy[e, 0] - cx
            dy = tail_xy[e, 1] + s[r, n] * step_xy[e, 1] - cy
            if dx * dx + dy * dy <= r2:
                hit = True
                acc += w[r, n] * p_fn
            else:
                acc += w[r, n]
        sums[i] = acc
        touched[i] = hit and p_fn != 1.0 and acc > 0.0
        if touched[i]:
            for n in range(n_count):
                e = edge[r, n]
                dx = tail_xy[e, 0] + s[r, n] * step_xy[e, 0] - cx
                dy = tail_xy[e, 1] + s[r, n] * step_xy[e, 1] - cy
                if dx * dx + dy * dy <= r2:
                    w[r, n] = w[r, n] * p_fn / acc
                else:
                    w[r, n] = w[r, n] / acc


@njit(cache=True)
def _store_row(edge: IntArray, s: FloatArray, w: FloatArray, r: int, new_edge: IntArray,
               new_s: FloatArray) -> None:
    """Row ``r`` becomes the resampled particles ``new_*``, each of weight ``1/N``."""
    n_count = edge.shape[1]
    for j in range(n_count):
        edge[r, j] = new_edge[j]
        s[r, j] = new_s[j]
        w[r, j] = 1.0 / n_count


@njit(cache=True)
def resample_rows(edge: IntArray, s: FloatArray, w: FloatArray, rows: IntArray,
                  u: FloatArray) -> None:
    """Low-variance resampling in place of the listed rows, row ``rows[i]`` with offset
    ``u[i]`` in ``[0, 1)``; the weights of those rows become ``1/N``.

    Output particle ``j`` copies the first input particle whose cumulative weight exceeds
    ``(u + j) / N`` (the last one if round-off leaves none), as
    :func:`~searchtrack.estimate.road_resampling.systematic_indices`.
    """
    n_count = edge.shape[1]
    new_edge = np.empty(n_count, dtype=edge.dtype)
    new_s = np.empty(n_count, dtype=s.dtype)
    for i in range(rows.size):
        r = rows[i]
        total = 0.0
        for n in range(n_count):
            total += w[r, n]
        k = 0
        c = w[r, 0] / total
        for j in range(n_count):
            target = (u[i] + j) / n_count
            while c <= target and k < n_count - 1:
                k += 1
                c += w[r, k] / total
            new_edge[j] = edge[r, k]
            new_s[j] = s[r, k]
        _store_row(edge, s, w, r, new_edge, new_s)


@njit(cache=True)
def join_rows(edge: IntArray, s: FloatArray, w: FloatArray, rows: IntArray, mass: FloatArray,
              add_edge: IntArray, add_s: FloatArray, add_w: FloatArray, u: FloatArray) -> None:
    """Join draws to the listed rows and resample each union back to ``N``, in place.

    Row ``rows[i]``'s particles weigh ``mass[i] · w`` and its draws ``add_*[i]`` ``(K,)`` weigh
    ``add_w[i]``; output ``j`` copies the first particle of the union (the row's, then its
    draws) whose cumulative weight exceeds ``(u[i] + j) / N`` of the total; weights become
    ``1/N``. A row whose union weighs nothing is left as it is.
    """
    n_count, k_count = edge.shape[1], add_edge.shape[1]
    new_edge = np.empty(n_count, dtype=edge.dtype)
    new_s = np.empty(n_count, dtype=s.dtype)
    for i in range(rows.size):
        r = rows[i]
        total = 0.0
        for n in range(n_count):
            total += w[r, n] * mass[i]
        for k in range(k_count):
            total += add_w[i, k]
        if not total > 0.0:
            continue
        idx = 0
        c = w[r, 0] * mass[i] / total
        for j in range(n_count):
            target = (u[i] + j) / n_count
            while c <= target and idx < n_count + k_count - 1:
                idx += 1
                c += (w[r, idx] * mass[i] if idx < n_count else add_w[i, idx - n_count]) / total
            if idx < n_count:
                new_edge[j] = edge[r, idx]
                new_s[j] = s[r, idx]
            else:
                new_edge[j] = add_edge[i, idx - n_count]
                new_s[j] = add_s[i, idx - n_count]
        _store_row(edge, s, w, r, new_edge, new_s)


@njit(cache=True)
def detection_jumps(cum_length: FloatArray, length: FloatArray, total_m: float,
                    tail_xy: FloatArray, step_xy: FloatArray, s0: FloatArray, inside: FloatArray,
                    cum_inside: FloatArray, l_disc: float, alpha: float, radius2: float,
                    yx: float, yy: float, gain: float, inv_two_var: float, floor: float,
                    scale: float, uniforms: FloatArray, edge: IntArray, s: FloatArray,
                    w: FloatArray) -> None:
    """Jump draws near a detection ``y`` into ``edge``, ``s`` and ``w`` ``(R, K)``: position ``x``
    from the proposal ``g`` (``uniforms[0] < α``: uniform by length, else uniform on the road
    inside the disc, ``inside`` long on each edge from ``s0``; ``uniforms[1]`` picks the edge,
    ``uniforms[2]`` the arc) and weight ``scale · p(y | x) · u(x) / g(x)`` (Eq. 10, ``floor``
    the clutter term; ``u = 1 / total_m``)."""
    n_edges = length.size
    span = cum_length[n_edges - 1]
    disc_span = cum_inside[n_edges - 1]
    for i in range(edge.shape[0]):
        for k in range(edge.shape[1]):
            if l_disc > 0.0 and uniforms[0, i, k] >= alpha:
                e = min(np.searchsorted(cum_inside, uniforms[1, i, k] * disc_span, side="right"),
                        n_edges - 1)
                arc = s0[e] + uniforms[2, i, k] * inside[e]
            else:
                e = min(np.searchsorted(cum_length, uniforms[1, i, k] * span, side="right"),
                        n_edges - 1)
                arc = uniforms[2, i, k] * length[e]
            dx = tail_xy[e, 0] + arc * step_xy[e, 0] - yx
            dy = tail_xy[e, 1] + arc * step_xy[e, 1] - yy
            d2 = dx * dx + dy * dy
            g = alpha / total_m
            if d2 <= radius2 and l_disc > 0.0:
                g += (1.0 - alpha) / l_disc
            z = d2 * inv_two_var
            lik = (gain * math.exp(-z) if z < _MAX_EXPONENT else 0.0) + floor
            edge[i, k] = e
            s[i, k] = arc
            w[i, k] = scale * lik * ((1.0 / total_m) / g)
