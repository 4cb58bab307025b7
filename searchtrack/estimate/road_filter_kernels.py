"""Numba kernels of the road particle filters (see :mod:`searchtrack.estimate.road_pf`).

Particle clouds are ``(F, N)`` arrays: directed edge ``edge``, arc length ``s`` (m) and
normalized weights ``w`` (each row sums to 1); row ``f`` holds ``count[f]`` particles in its
first columns, and the kernels skip the columns beyond (weight 0, see
:mod:`searchtrack.estimate.road_resample_kernels`, which holds the resampling kernels). A
particle's planar point ``G(x)`` is ``tail_xy[e] + s · step_xy[e]``
(:class:`~searchtrack.models.road_particles.DirectedRoads`).
Random numbers are drawn by the caller's ``numpy.random.Generator`` and passed in. The NumPy
references are :meth:`~searchtrack.models.disc_sensor.DiscSensor.likelihood`,
:meth:`~searchtrack.models.disc_sensor.DiscSensor.miss_likelihood`,
:func:`~searchtrack.estimate.road_resampling.systematic_indices`,
:func:`~searchtrack.estimate.road_jumps.near_detection`,
:func:`~searchtrack.estimate.road_jumps.gaussian_integral_reference`,
:meth:`~searchtrack.models.road_particles.DirectedRoads.disc_intervals`,
:meth:`~searchtrack.models.road_particles.DirectedRoads.uniform` and
:meth:`~searchtrack.models.road_particles.RoadMotion.step` (the motion kernels draw what it
draws, in the same order, so a seed moves the particles alike).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from searchtrack.core.types import FloatArray, IntArray

#: Beyond this exponent a Gaussian term (Eq. 10, the kernels of the draws near detections) is
#: below 1e-304 of its peak: skip ``exp``.
MAX_EXPONENT = 700.0


@njit(cache=True)
def detection_likelihood(edge: IntArray, s: FloatArray, w: FloatArray, count: IntArray,
                         tail_xy: FloatArray, step_xy: FloatArray, yx: float, yy: float,
                         gain: float, inv_two_var: float, floor: float, lik: FloatArray,
                         sums: FloatArray) -> None:
    """Eq. 10 for every particle into ``lik`` ``(F, N)`` (0 beyond a row's count), and
    ``sums[f] = Σ_n w p(y | x)`` (Eq. 16) per row:
    ``p = gain · exp(−‖G(x) − y‖² · inv_two_var) + floor``."""
    f_count, n_count = edge.shape
    for f in range(f_count):
        acc = 0.0
        for n in range(count[f], n_count):
            lik[f, n] = 0.0
        for n in range(count[f]):
            e = edge[f, n]
            dx = tail_xy[e, 0] + s[f, n] * step_xy[e, 0] - yx
            dy = tail_xy[e, 1] + s[f, n] * step_xy[e, 1] - yy
            q = (dx * dx + dy * dy) * inv_two_var
            p = floor
            if q < MAX_EXPONENT:
                p += gain * math.exp(-q)
            lik[f, n] = p
            acc += w[f, n] * p
        sums[f] = acc


@njit(cache=True)
def weigh_rows(w: FloatArray, lik: FloatArray, rows: IntArray, count: IntArray) -> None:
    """Bayes' rule (Eq. 4, Eq. 6) on the listed rows: ``w ← w · lik``, normalized; a row whose
    product is all zero is left unchanged (the measurement cannot tell its particles apart)."""
    for r in rows:
        n_count = count[r]
        acc = 0.0
        for n in range(n_count):
            acc += w[r, n] * lik[r, n]
        if acc > 0.0:
            for n in range(n_count):
                w[r, n] = w[r, n] * lik[r, n] / acc


@njit(cache=True)
def miss_update(edge: IntArray, s: FloatArray, w: FloatArray, count: IntArray, rows: IntArray,
                tail_xy: FloatArray, step_xy: FloatArray, cx: float, cy: float, r2: float,
                p_fn: float, sums: FloatArray, touched: np.ndarray) -> None:
    """Negative information (Eq. 11 as intended) on the listed rows: weights of particles within
    ``√r2`` of ``(cx, cy)`` are multiplied by ``p_fn``, then the row is normalized.

    ``sums[i]`` gets the row's no-detection likelihood ``Σ_n w p(z | x)`` (before normalizing)
    and ``touched[i]`` whether any weight changed; a row whose likelihood is 0 is left as is.
    """
    for i in range(rows.size):
        r = rows[i]
        n_count = count[r]
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
            lik = (gain * math.exp(-z) if z < MAX_EXPONENT else 0.0) + floor
            edge[i, k] = e
            s[i, k] = arc
            w[i, k] = scale * lik * ((1.0 / total_m) / g)


@njit(cache=True)
def disc_intervals(tail_xy: FloatArray, step_xy: FloatArray, length: FloatArray, cx: float,
                   cy: float, radius: float, s0: FloatArray, s1: FloatArray) -> float:
    """The arc ``[s0, s1]`` of every directed edge inside the disc of ``radius`` around
    ``(cx, cy)`` into ``s0`` and ``s1`` (equal where the edge misses it), and the road length
    in the disc; the NumPy reference is :meth:`~searchtrack.models.road_particles.
    DirectedRoads.disc_intervals`."""
    total = 0.0
    r2 = radius * radius
    for e in range(length.size):
        abx = step_xy[e, 0] * length[e]
        aby = step_xy[e, 1] * length[e]
        relx = tail_xy[e, 0] - cx
        rely = tail_xy[e, 1] - cy
        a2 = max(abx * abx + aby * aby, 1e-300)
        b = (abx * relx + aby * rely) / a2
        disc = b * b - ((relx * relx + rely * rely) - r2) / a2
        root = math.sqrt(max(disc, 0.0))
        t0 = min(max(-b - root, 0.0), 1.0)
        t1 = min(max(-b + root, 0.0), 1.0)
        t1 = max(t1, t0) if disc > 0.0 else t0
        s0[e] = t0 * length[e]
        s1[e] = t1 * length[e]
        total += s1[e] - s0[e]
    return total


@njit(cache=True)
def systematic_row(w: FloatArray, u: float) -> IntArray:
    """Systematic resampling of one row of weights ``w`` ``(N,)`` (positive sum) with offset
    ``u`` in ``[0, 1)``: the ``(N,)`` indices of
    :func:`~searchtrack.estimate.road_resampling.systematic_indices` for that row."""
    n = w.size
    total = 0.0
    for k in range(n):
        total += w[k]
    cum = np.empty(n)
    c = 0.0
    for k in range(n):
        c += w[k] / total
        cum[k] = c
    cum[n - 1] = 1.0
    out = np.empty(n, dtype=np.int64)
    k = 0
    for j in range(n):
        target = (u + j) / n
        while k < n - 1 and cum[k] <= target:
            k += 1
        out[j] = k
    return out


@njit(cache=True)
def miss_jumps(cum_length: FloatArray, length: FloatArray, tail_xy: FloatArray,
               step_xy: FloatArray, ux: float, uy: float, radius2: float, p_fn: float,
               scale: float, uniforms: FloatArray, edge: IntArray, s: FloatArray,
               w: FloatArray) -> None:
    """Jump draws of a miss into ``edge``, ``s`` and ``w`` ``(R, K)``: position ``x`` uniform by
    length (``uniforms[0]`` picks the edge, ``uniforms[1]`` the arc, as
    :meth:`~searchtrack.models.road_particles.DirectedRoads.uniform`) and weight
    ``scale · p(z | x)`` (Eq. 11: ``P_FN`` within ``√radius2`` of the UAV at ``(ux, uy)``, else
    1)."""
    n_edges = length.size
    span = cum_length[n_edges - 1]
    for i in range(edge.shape[0]):
        for k in range(edge.shape[1]):
            e = min(np.searchsorted(cum_length, uniforms[0, i, k] * span, side="right"),
                    n_edges - 1)
            arc = uniforms[1, i, k] * length[e]
            dx = tail_xy[e, 0] + arc * step_xy[e, 0] - ux
            dy = tail_xy[e, 1] + arc * step_xy[e, 1] - uy
            edge[i, k] = e
            s[i, k] = arc
            w[i, k] = scale * (p_fn if dx * dx + dy * dy <= radius2 else 1.0)


@njit(cache=True)
def move(edge: IntArray, s: FloatArray, normals: FloatArray, speed: float, sigma: float,
         dt: float, length: FloatArray, count: IntArray) -> IntArray:
    """Eq. 9 in place on flat ``s`` (rows of ``s.size / count.size`` columns, the columns
    beyond a row's ``count`` left as they are): ``s += max(speed + sigma · normal, 0) · dt``;
    returns the indices of the particles now past the end of their edge (for :func:`turn`).
    With :func:`turn`, the kernel form of
    :meth:`~searchtrack.models.road_particles.RoadMotion.step` from the same normals and turn
    uniforms."""
    over = np.empty(s.size, dtype=np.int64)
    k = 0
    n_cap = s.size // count.size
    for f in range(count.size):
        for i in range(f * n_cap, f * n_cap + count[f]):
            s[i] = s[i] + max(speed + sigma * normals[i], 0.0) * dt
            if s[i] > length[edge[i]]:
                over[k] = i
                k += 1
    return over[:k]


@njit(cache=True)
def turn(edge: IntArray, s: FloatArray, over: IntArray, u: FloatArray, length: FloatArray,
         successors: IntArray, successor_ptr: IntArray) -> IntArray:
    """Carry the particles ``over`` (flat indices past their edge's end) onto a successor
    edge picked by ``u`` ``(len(over),)`` in ``[0, 1)``, keeping the leftover arc; returns
    those still past the end of their new edge."""
    left = np.empty(over.size, dtype=np.int64)
    k = 0
    for j in range(over.size):
        i = over[j]
        d = edge[i]
        s[i] -= length[d]
        count = successor_ptr[d + 1] - successor_ptr[d]
        edge[i] = successors[successor_ptr[d] + np.int64(u[j] * count)]
        if s[i] > length[edge[i]]:
            left[k] = i
            k += 1
    return left[:k]


@njit(cache=True)
def courier_move(edge: IntArray, s: FloatArray, v: FloatArray, mode: FloatArray,
                 u: FloatArray, stop: float, go: float, lo: float, hi: float, dt: float,
                 length: FloatArray, count: IntArray) -> IntArray:
    """:class:`~searchtrack.models.road_particles.CourierRoadMotion` in place on flat arrays
    (rows as :func:`move`): switch each particle's mode by ``mode`` (stop below ``stop`` if
    driving, drive off below ``go`` at ``lo + u (hi − lo)`` if stopped), move it ``v·dt``;
    returns the indices of the particles past the end of their edge (for :func:`turn`)."""
    over = np.empty(s.size, dtype=np.int64)
    k = 0
    n_cap = s.size // count.size
    for f in range(count.size):
        for i in range(f * n_cap, f * n_cap + count[f]):
            if v[i] > 0.0:
                if mode[i] < stop:
                    v[i] = 0.0
            elif mode[i] < go:
                v[i] = lo + u[i] * (hi - lo)
            else:
                v[i] = 0.0
            s[i] = s[i] + v[i] * dt
            if s[i] > length[edge[i]]:
                over[k] = i
                k += 1
    return over[:k]


@njit(cache=True)
def gaussian_road_integral(tail_xy: FloatArray, step_xy: FloatArray, length: FloatArray,
                           yx: float, yy: float, sigma2: float) -> float:
    """``∫ exp(−‖G(x) − y‖² / 2σ²) dx`` over the directed roads (m): per edge, with ``h`` the
    distance from ``y`` to its line and ``t*`` the arc of the foot point,
    ``exp(−h²/2σ²) σ √(π/2) [erf((ℓ − t*)/σ√2) + erf(t*/σ√2)]``."""
    scale = math.sqrt(2.0 * sigma2)
    total = 0.0
    for e in range(length.size):
        rx, ry = yx - tail_xy[e, 0], yy - tail_xy[e, 1]
        t = rx * step_xy[e, 0] + ry * step_xy[e, 1]
        h2 = max(rx * rx + ry * ry - t * t, 0.0)
        if 0.5 * h2 / sigma2 > MAX_EXPONENT:
            continue
        total += math.exp(-0.5 * h2 / sigma2) * (math.erf((length[e] - t) / scale)
                                                 + math.erf(t / scale))
    return total * math.sqrt(0.5 * math.pi * sigma2)
