"""Compiled passes of the SMC-PHD filter over its particles (numba, ``cache=True``).

The NumPy equations of :mod:`~searchtrack.estimate.phd.predict`,
:mod:`~searchtrack.estimate.phd.update` and :mod:`~searchtrack.estimate.phd.resample` (Vo, Singh &
Doucet 2005; paper 003, eqs. 4–5) build ``(k, N)`` arrays for ``k`` measurements and ``N``
particles. These kernels visit each particle a bounded number of times instead, in fixed chunks
of :data:`CHUNK` particles run in parallel (``prange``); every sum over particles is a sum of
per-chunk partial sums in chunk order, so results do not depend on the number of threads.

*Measurement gate, exact by construction.* The position sensor's Gaussian
``g(z|x) = N(z; x, σ² I)`` is held at its value ``F = g`` at ``TAIL_SIGMAS`` standard deviations
beyond them (:class:`~searchtrack.models.position_sensor.PositionSensor`). With
``u_i = p_d(x_i) w_i`` every sum of the update splits into the constant floor and a gated part::

    Σ_i g(z|x_i) u_i = F Σ_i u_i + Σ_{i: ‖z − x_i‖ < 9σ} (g(z|x_i) − F) u_i

and likewise for the term means ``Σ_i A_{z,i} x_i`` and the per-group sums. Only measurement–
particle pairs inside the gate are evaluated (found through a grid of cells, each listing the
measurements within the gate of it), and the floor is added once per measurement: the same
update as the dense ``(k, N)`` arrays up to floating-point rounding. Each particle's strongest
term (the ``argmax_z`` attribution) is the better of its strongest gated term and the floor term
of the measurement with the smallest ``C_z``.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from searchtrack.core.types import FloatArray, IntArray

CHUNK = 16384


def n_chunks(n: int) -> int:
    """Number of :data:`CHUNK`-sized chunks covering ``n`` particles."""
    return max(1, -(-n // CHUNK))


@nb.njit(cache=True, inline="always")
def _moved(src: FloatArray, e: FloatArray, i: int, j: int, p: int, dt: float, a: float,
           b: float, c: float, noise: bool, col: int) -> float:
    """Column ``col`` of particle ``i`` after the nearly-constant-velocity move with noise row
    ``j`` (the operations of
    :meth:`~searchtrack.models.motion.ConstantVelocity.propagate`, in its order)."""
    v: float = src[i, col]
    if col < p:
        v = v + dt * src[i, col + p]
        if noise:
            v += a * e[j, col]
    elif noise:
        v += b * e[j, col - p] + c * e[j, col]
    return v


@nb.njit(cache=True, parallel=True)
def move_compact(src: FloatArray, e: FloatArray, e_row: int, move: bool, noise: bool,
                 dt: float, a: float, b: float, c: float, p: int, w: FloatArray,
                 survival: FloatArray, tags: IntArray, label: int, lo: FloatArray,
                 hi: FloatArray, out_x: FloatArray, out_w: FloatArray, out_labels: IntArray,
                 out_tags: IntArray, offset: int) -> int:
    """Move ``src`` (noise rows ``e[e_row:]``), weight ``w · survival`` (one survival value or
    one per particle), keep the particles inside ``[lo, hi]`` and write them in order from
    ``offset`` of the outputs; returns how many were kept."""
    n, d = src.shape
    nc = max(1, -(-n // CHUNK))
    counts = np.zeros(nc + 1, dtype=np.int64)
    for ch in nb.prange(nc):
        kept = 0
        for i in range(ch * CHUNK, min(n, (ch + 1) * CHUNK)):
            ok = True
            for col in range(p):
                v = _moved(src, e, i, e_row + i, p, dt, a, b, c, noise, col) if move \
                    else src[i, col]
                if not (v >= lo[col] and v <= hi[col]):
                    ok = False
            kept += ok
        counts[ch + 1] = kept
    for ch in range(nc):
        counts[ch + 1] += counts[ch]
    one = survival.shape[0] == 1
    for ch in nb.prange(nc):
        k = offset + counts[ch]
        row = np.empty(d)
        for i in range(ch * CHUNK, min(n, (ch + 1) * CHUNK)):
            ok = True
            for col in range(d):
                v = _moved(src, e, i, e_row + i, p, dt, a, b, c, noise, col) if move \
                    else src[i, col]
                row[col] = v
                if col < p and not (v >= lo[col] and v <= hi[col]):
                    ok = False
            if ok:
                out_x[k, :] = row
                out_w[k] = w[i] * (survival[0] if one else survival[i])
                out_labels[k] = label
                out_tags[k] = tags[i]
                k += 1
    return int(counts[nc])


@nb.njit(cache=True)
def cumulative(w: FloatArray) -> FloatArray:
    """Running sums of ``w`` in order (``numpy.cumsum``'s additions)."""
    out = np.empty(w.shape[0])
    t = 0.0
    for i in range(w.shape[0]):
        t += w[i]
        out[i] = t
    return out


@nb.njit(cache=True, parallel=True)
def systematic_gather(cum: FloatArray, u: float, n: int, x: FloatArray, labels: IntArray,
                      tags: IntArray) -> tuple[FloatArray, IntArray, IntArray]:
    """Systematic resampling (Thrun, Burgard & Fox 2005, Table 4.4) of ``n`` particles from the
    cumulative weights ``cum`` with offset ``u``: pointer ``m`` is ``(u + m) · cum[-1] / n`` and
    picks the first particle whose cumulative weight exceeds it (``searchsorted``, side
    ``"right"``), found by a merge of the sorted pointers in chunks; the picked states, labels
    and tags are copied once into the new arrays."""
    big, d = x.shape
    step = cum[big - 1] / n
    out_x = np.empty((n, d))
    out_l = np.empty(n, dtype=np.int64)
    out_t = np.empty(n, dtype=np.int64)
    nc = max(1, -(-n // CHUNK))
    for ch in nb.prange(nc):
        m0 = ch * CHUNK
        j = np.searchsorted(cum, (u + m0) * step, side="right")
        for m in range(m0, min(n, m0 + CHUNK)):
            ptr = (u + m) * step
            while j < big and cum[j] <= ptr:
                j += 1
            i = min(j, big - 1)
            out_x[m, :] = x[i, :]
            out_l[m] = labels[i]
            out_t[m] = tags[i]
    return out_x, out_l, out_t
