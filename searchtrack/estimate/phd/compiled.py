"""The ``"numba"`` backend of the SMC-PHD filter: its predict, update and resample steps on
the compiled passes of :mod:`searchtrack.estimate.phd.kernels` and
:mod:`searchtrack.estimate.phd.gated`.

Each function takes the same random draws from the generator, in the same order, as the NumPy
equations it replaces, so both backends give the same particles up to floating-point rounding.
The prediction covers the nearly-constant-velocity motion
(:class:`~searchtrack.models.motion.ConstantVelocity`), the update the Gaussian position sensor
(:class:`~searchtrack.models.position_sensor.PositionSensor`); the callers use the NumPy
equations for other models.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from searchtrack.core.kernel_threads import threads_for
from searchtrack.core.types import FloatArray, IntArray
from searchtrack.estimate.phd import gated, kernels
from searchtrack.models.motion import ConstantVelocity
from searchtrack.models.position_sensor import TAIL_SIGMAS, PositionSensor

if TYPE_CHECKING:
    from searchtrack.estimate.phd.update import SensorScan

CELLS_PER_GATE = 4
"""Grid cells per gate width: a particle's candidate measurements are those within the gate of
its cell, about ``(1 + 2 / CELLS_PER_GATE)²`` times the gate's square instead of the 3 × 3 cells
around it at one cell per gate."""
MAX_CELLS = 256
"""At most this many grid cells per axis."""


@dataclass(frozen=True)
class Block:
    """Particles entering the prediction: states, weights, survival (one value or one per
    particle), tags and label; ``moved`` says whether the motion model moves them."""

    states: FloatArray
    weights: FloatArray
    survival: FloatArray
    tags: IntArray
    label: int
    moved: bool


def predict_blocks(blocks: Sequence[Block], motion: ConstantVelocity, dt_s: float,
                   noise: FloatArray | None, region: FloatArray | None,
                   ) -> tuple[FloatArray, FloatArray, IntArray, IntArray]:
    """Move the ``moved`` blocks by ``motion`` with the rows of ``noise`` in block order
    (``None``: no noise, ``dt_s = 0``), weight by survival and keep those inside ``region``:
    ``(states, weights, labels, tags)`` in block order, written once."""
    p = motion.position_dim
    d = 2 * p
    total = sum(b.states.shape[0] for b in blocks)
    out_x = np.empty((total, d))
    out_w = np.empty(total)
    out_l = np.empty(total, dtype=np.int64)
    out_t = np.empty(total, dtype=np.int64)
    lo = np.full(p, -np.inf) if region is None else np.ascontiguousarray(region[:, 0])
    hi = np.full(p, np.inf) if region is None else np.ascontiguousarray(region[:, 1])
    q, dt = motion.q, float(dt_s)
    a, b, c = (math.sqrt(q * dt**3 / 3.0), math.sqrt(3.0 * q * dt) / 2.0,
               math.sqrt(q * dt / 4.0))
    e = np.empty((0, d)) if noise is None else noise
    kept = row = 0
    for blk in blocks:
        with threads_for(blk.states.size):
            kept += kernels.move_compact(
                np.ascontiguousarray(blk.states, dtype=np.float64), e, row, blk.moved,
                noise is not None, dt, a, b, c, p, np.ascontiguousarray(blk.weights),
                np.ascontiguousarray(blk.survival, dtype=np.float64), blk.tags, blk.label, lo,
                hi, out_x, out_w, out_l, out_t, kept)
        row += blk.states.shape[0] if blk.moved else 0
    return out_x[:kept], out_w[:kept], out_l[:kept], out_t[:kept]


def systematic(weights: FloatArray, n: int, u: float, states: FloatArray, labels: IntArray,
               tags: IntArray) -> tuple[FloatArray, IntArray, IntArray]:
    """The states, labels and tags of ``n`` particles drawn by systematic resampling with offset
    ``u`` (the indices of :func:`~searchtrack.estimate.phd.resample.systematic_indices`)."""
    cum = kernels.cumulative(np.ascontiguousarray(weights))
    with threads_for(n * states.shape[1]):
        return kernels.systematic_gather(cum, u, n, np.ascontiguousarray(states), labels, tags)


def gate_grid(sensor: PositionSensor, z: FloatArray) -> tuple[FloatArray, FloatArray, IntArray,
                                                               IntArray, IntArray]:
    """Cells over the sensor's area about a :data:`CELLS_PER_GATE`-th of the gate
    (``TAIL_SIGMAS`` σ) wide (at most :data:`MAX_CELLS` per axis), and per cell the measurements
    within the gate of it: ``(low corner, cell size, shape, start, order)``."""
    lo = np.ascontiguousarray(sensor.area[:, 0])
    width = sensor.area[:, 1] - sensor.area[:, 0]
    gate = TAIL_SIGMAS * sensor.sigma_m * (1.0 + 1e-9)
    shape = np.clip(np.floor(width * CELLS_PER_GATE / gate), 1, MAX_CELLS).astype(np.int64)
    size = width / shape
    start, order = gated.measurement_grid(np.ascontiguousarray(z), lo, size, shape, gate)
    return lo, size, shape, start, order


def gated_supported(x: FloatArray, scans: Sequence[SensorScan]) -> bool:
    """Whether the gated passes cover this update: position sensors only, 2-D positions."""
    return (x.shape[0] > 0 and x.shape[1] >= 2 and len(scans) > 0
            and all(type(s.sensor) is PositionSensor for s in scans))


@dataclass
class Corrections:
    """What the sensors' updates leave for the record and the tags (see
    :mod:`searchtrack.estimate.phd.update`): the new weights; per particle its attributed mass,
    strongest term and that term's measurement; per measurement (all sensors in order) the mass
    ``ρ_z``, term mean, birth seed and dominant tag group; per slot (tag + 1) the sums
    ``[prior, attributed, rest, rest · x]`` after the last sensor."""

    weights: FloatArray
    attributed: FloatArray
    best_share: FloatArray
    owner: IntArray
    rhos: list[FloatArray]
    means: list[FloatArray]
    seeds: list[FloatArray]
    groups: list[IntArray]
    slot_sums: FloatArray


def gated_corrections(x: FloatArray, prior: FloatArray, tags: IntArray,
                      scans: Sequence[SensorScan]) -> Corrections:
    """The sequential update of ``scans`` (position sensors) on particles ``x`` with weights
    ``prior`` and tags ``tags``, by the two gated passes per sensor."""
    x = np.ascontiguousarray(x, dtype=np.float64)
    n = x.shape[0]
    n_slots = int(tags.max(initial=-1)) + 2
    out = Corrections(np.ascontiguousarray(prior), np.zeros(n), np.zeros(n),
                      np.full(n, -1, dtype=np.int64), [], [], [], [], np.empty(0))
    offset = 0
    for idx, scan in enumerate(scans):
        sensor = scan.sensor
        assert isinstance(sensor, PositionSensor)
        z = np.ascontiguousarray(scan.measurements)
        k = z.shape[0]
        s2 = sensor.sigma_m**2
        qscale, qmin = -0.5 / s2, -0.5 * TAIL_SIGMAS**2
        norm = 1.0 / (2.0 * math.pi * s2)
        floor = float(np.exp(np.float64(qmin))) * norm
        lo, size, shape, start, order = gate_grid(sensor, z)
        area = np.ascontiguousarray(sensor.area)
        cp = np.ones(1)
        inv_sum, zstar = 0.0, 0
        work = x.shape[0] * max(k, 1)  # both passes sweep particles × measurements
        if k:
            with threads_for(work):
                su, sux, sus, gz, gzx, gzs = gated.gate_sums(
                    x, out.weights, sensor.pd, area, z, qscale, qmin, norm, floor, lo, size,
                    shape, start, order, tags, n_slots)
            explained = floor * su.sum() + gz.sum(axis=0)
            c = sensor.clutter_intensity(scan.pose, z) + explained
            cp = np.where(c > 0.0, c, 1.0)
            inv_sum, zstar = float((1.0 / cp).sum()), int(np.argmin(cp))
            means = (floor * sux.sum(axis=0) + gzx.sum(axis=0)) / cp[:, None]
            groups = np.full(k, -1, dtype=np.int64)
            if n_slots > 1:
                per_group = (floor * sus.sum(axis=0) + gzs.sum(axis=0)) / cp[:, None]
                groups = np.asarray(np.argmax(per_group, axis=1) - 1, dtype=np.int64)
            out.groups.append(groups)
            out.seeds.append(sensor.to_position(scan.pose, z))
        with threads_for(work):
            out.weights, sums, rz = gated.correct_particles(
                x, out.weights, prior, sensor.pd, area, z, cp, qscale, qmin, norm, floor,
                inv_sum, zstar, lo, size, shape, start, order, out.attributed, out.best_share,
                out.owner, offset, tags, n_slots, idx == len(scans) - 1)
        out.slot_sums = sums.sum(axis=0)
        if k:
            rho = (floor * su.sum()) / cp + rz.sum(axis=0)
            out.rhos.append(rho)
            out.means.append(means / np.where(rho > 0.0, rho, 1.0)[:, None])
        offset += k
    return out
