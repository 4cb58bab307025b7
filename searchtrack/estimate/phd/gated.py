"""The gated SMC-PHD update as compiled passes over the particles (numba, ``cache=True``).

For one position sensor with measurements ``Z`` (paper 003, eq. 5; Vo, Singh & Doucet 2005)::

    u_i = p_d(x_i) w_i,   C_z = c(z) + Σ_i g(z|x_i) u_i,   A_{z,i} = g(z|x_i) u_i / C_z
    w_i ← (1 − p_d(x_i)) w_i + Σ_z A_{z,i}

where ``g`` is held at its floor ``F`` beyond ``TAIL_SIGMAS`` standard deviations (see
:mod:`searchtrack.estimate.phd.kernels` for why the gate below is exact). :func:`gate_sums` is the
first pass: per chunk of particles, ``Σ u``, ``Σ u x`` and ``Σ u`` per tag group, and per
measurement the gated parts ``Σ (g − F) u`` of ``C_z``, of the term mean and of the per-group
sums. :func:`correct_particles` is the second: each particle's new weight, the mass the
measurements take from it, its strongest term (for the tags) and, after the last sensor, the
per-group sums of the missed-target read-out. :func:`final_tags` is the tagging of the update.
Candidate pairs come from a grid of cells a fraction of the gate wide: each cell lists the
measurements within the gate of it (:func:`measurement_grid`), so a particle visits one list.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from searchtrack.core.kernel_cache import follow_callees
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.phd.kernels import CHUNK


@nb.njit(cache=True, inline="always")
def _cell(v: float, lo: float, inv: float, m: int) -> int:
    """Grid cell of coordinate ``v`` on an axis of cells ``1 / inv`` wide from ``lo``, clamped to
    ``[0, m)``."""
    q = (v - lo) * inv
    if not q >= 0.0:
        return 0
    return min(int(q), m - 1)


@nb.njit(cache=True, inline="always")
def _grid_cell(x0: float, x1: float, glo: FloatArray, inv0: float, inv1: float,
               gshape: IntArray) -> int:
    """Flat index of the grid cell of the point ``(x0, x1)``."""
    cols: int = gshape[1]
    return _cell(x0, glo[0], inv0, gshape[0]) * cols + _cell(x1, glo[1], inv1, cols)


@nb.njit(cache=True, inline="always")
def _exponent(z: FloatArray, j: int, x0: float, x1: float, qscale: float) -> float:
    """The Gaussian's exponent ``qscale · ‖z_j − (x0, x1)‖²`` (summed in this order)."""
    e: float = z[j, 0] - x0
    e *= e
    dy: float = z[j, 1] - x1
    e += dy * dy
    return e * qscale


@nb.njit(cache=True)
def measurement_grid(z: FloatArray, lo: FloatArray, size: FloatArray, shape: IntArray,
                     gate: float) -> tuple[IntArray, IntArray]:
    """Per grid cell the measurements within ``gate`` of the cell (CSR: ``start[cell]:start[cell
    + 1]`` of ``order``, increasing measurement index within a cell). The border cells reach to
    infinity outwards, since :func:`_cell` clamps, and every cell is widened by a millionth of
    its size against rounding, so a particle's cell lists every measurement within ``gate`` of
    it."""
    k = z.shape[0]
    m0, m1 = shape[0], shape[1]
    g2 = gate * gate
    start = np.zeros(m0 * m1 + 1, dtype=np.int64)
    for rnd in range(2):
        fill = start[:-1].copy()
        order = np.empty(start[m0 * m1], dtype=np.int64)
        for j in range(k):
            z0, z1 = z[j, 0], z[j, 1]
            for a0 in range(_cell(z0 - gate, lo[0], 1.0 / size[0], m0),
                            _cell(z0 + gate, lo[0], 1.0 / size[0], m0) + 1):
                e0 = _outside(z0, a0, lo[0], size[0], m0)
                for a1 in range(_cell(z1 - gate, lo[1], 1.0 / size[1], m1),
                                _cell(z1 + gate, lo[1], 1.0 / size[1], m1) + 1):
                    e1 = _outside(z1, a1, lo[1], size[1], m1)
                    if e0 * e0 + e1 * e1 <= g2:
                        q = a0 * m1 + a1
                        if rnd == 0:
                            start[q + 1] += 1
                        else:
                            order[fill[q]] = j
                            fill[q] += 1
        if rnd == 0:
            for q in range(m0 * m1):
                start[q + 1] += start[q]
    return start, order


@nb.njit(cache=True, inline="always")
def _outside(v: float, a: int, lo: float, size: float, m: int) -> float:
    """How far ``v`` lies outside cell ``a`` of an axis (0 inside), the cell widened by a
    millionth of its size and the border cells reaching to infinity."""
    pad = 1e-6 * size
    low = lo + a * size - pad
    high = lo + (a + 1) * size + pad
    if a > 0 and v < low:
        return low - v
    if a < m - 1 and v > high:
        return v - high
    return 0.0


@nb.njit(cache=True, parallel=True)
def gate_sums(x: FloatArray, w: FloatArray, pd: float, area: FloatArray, z: FloatArray,
               qscale: float, qmin: float, norm: float, floor: float, glo: FloatArray,
               gsize: FloatArray, gshape: IntArray, start: IntArray, order: IntArray,
               tags: IntArray, n_slots: int) -> tuple[FloatArray, FloatArray, FloatArray,
                                                       FloatArray, FloatArray, FloatArray]:
    """First pass: per chunk ``Σ u``, ``Σ u x``, ``Σ u`` per slot (tag + 1), and per measurement
    ``Σ (g − F) u``, ``Σ (g − F) u x`` and ``Σ (g − F) u`` per slot over the gated pairs."""
    n, d = x.shape
    k = z.shape[0]
    nc = max(1, -(-n // CHUNK))
    su = np.zeros(nc)
    sux = np.zeros((nc, d))
    sus = np.zeros((nc, n_slots))
    gz = np.zeros((nc, k))
    gzx = np.zeros((nc, k, d))
    gzs = np.zeros((nc, k, n_slots))
    inv0, inv1 = 1.0 / gsize[0], 1.0 / gsize[1]
    for ch in nb.prange(nc):
        for i in range(ch * CHUNK, min(n, (ch + 1) * CHUNK)):
            x0, x1 = x[i, 0], x[i, 1]
            inside = area[0, 0] <= x0 <= area[0, 1] and area[1, 0] <= x1 <= area[1, 1]
            u = (pd if inside else 0.0) * w[i]
            if u == 0.0:
                continue
            s = tags[i] + 1
            su[ch] += u
            sus[ch, s] += u
            for col in range(d):
                sux[ch, col] += u * x[i, col]
            q = _grid_cell(x0, x1, glo, inv0, inv1, gshape)
            for t in range(start[q], start[q + 1]):
                j = order[t]
                e = _exponent(z, j, x0, x1, qscale)
                if e > qmin:
                    v = (np.exp(e) * norm - floor) * u
                    gz[ch, j] += v
                    gzs[ch, j, s] += v
                    for col in range(d):
                        gzx[ch, j, col] += v * x[i, col]
    return su, sux, sus, gz, gzx, gzs


@nb.njit(cache=True, parallel=True)
def correct_particles(x: FloatArray, w: FloatArray, prior: FloatArray, pd: float,
                      area: FloatArray, z: FloatArray, cz: FloatArray, qscale: float,
                      qmin: float, norm: float, floor: float, inv_sum: float, zstar: int,
                      glo: FloatArray, gsize: FloatArray, gshape: IntArray, start: IntArray,
                      order: IntArray, attributed: FloatArray, best_share: FloatArray,
                      owner: IntArray, offset: int, tags: IntArray, n_slots: int,
                      last: bool) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Second pass: the new weights ``(1 − p_d) w + Σ_z A_{z,i}`` (``cz``: the ``C_z``, 1 where
    0; ``inv_sum = Σ_z 1 / C_z``; ``zstar`` the first smallest ``C_z``); adds ``Σ_z A_{z,i}`` to
    ``attributed`` and raises ``best_share``/``owner`` (``offset`` + measurement) where a term is
    larger. After the last sensor also returns per chunk and slot ``[Σ prior, Σ attributed,
    Σ rest, Σ rest · x]`` with ``rest = max(w − attributed, 0)``, and per chunk and measurement
    the gated part ``Σ (g − F) u / C_z`` of its mass ``ρ_z`` (summed term by term, as the dense
    update sums ``A_{z,i}``)."""
    n, d = x.shape
    k = z.shape[0]
    nc = max(1, -(-n // CHUNK))
    out = np.empty(n)
    sums = np.zeros((nc, n_slots, 3 + d) if last else (nc, 0, 3 + d))
    rz = np.zeros((nc, k))
    inv0, inv1 = 1.0 / gsize[0], 1.0 / gsize[1]
    for ch in nb.prange(nc):
        for i in range(ch * CHUNK, min(n, (ch + 1) * CHUNK)):
            x0, x1 = x[i, 0], x[i, 1]
            inside = area[0, 0] <= x0 <= area[0, 1] and area[1, 0] <= x1 <= area[1, 1]
            pdi = pd if inside else 0.0
            u = pdi * w[i]
            took = 0.0
            if u != 0.0 and k > 0:
                took = u * (floor * inv_sum)
                best = (floor * u) / cz[zstar]
                jbest = zstar
                q = _grid_cell(x0, x1, glo, inv0, inv1, gshape)
                for t in range(start[q], start[q + 1]):
                    j = order[t]
                    e = _exponent(z, j, x0, x1, qscale)
                    if e > qmin:
                        g = np.exp(e) * norm
                        part = ((g - floor) * u) / cz[j]
                        took += part
                        rz[ch, j] += part
                        share = (g * u) / cz[j]
                        if share > best or (share == best and j < jbest):
                            best, jbest = share, j
                if best > best_share[i]:
                    best_share[i] = best
                    owner[i] = jbest + offset
                attributed[i] += took
            out[i] = (1.0 - pdi) * w[i] + took
            if last:
                s = tags[i] + 1
                rest = max(out[i] - attributed[i], 0.0)
                sums[ch, s, 0] += prior[i]
                sums[ch, s, 1] += attributed[i]
                sums[ch, s, 2] += rest
                for col in range(d):
                    sums[ch, s, 3 + col] += rest * x[i, col]
    return out, sums, rz


@nb.njit(cache=True, parallel=True)
def final_tags(best_share: FloatArray, w: FloatArray, owner: IntArray, keeper: IntArray,
               member: IntArray, tags: IntArray, offset: int) -> IntArray:
    """Each particle's tag: the kept measurement of its strongest term when that term is more
    than half its weight, else ``offset`` + its missed group's index when that group passes the
    threshold (``member`` per slot, -1 for none), else -1."""
    n = w.shape[0]
    out = np.empty(n, dtype=np.int64)
    for i in nb.prange(n):
        t = -1
        if best_share[i] > 0.5 * w[i] and owner[i] >= 0:
            t = keeper[owner[i]]
        if t < 0:
            m = member[tags[i] + 1]
            if m >= 0:
                t = offset + m
        out[i] = t
    return out


follow_callees(__name__, globals())
