"""The exploration bonus and the refinement terms of paper 004 (§4.1, eqs. 9–11).

The bonus ``ι`` lives on a grid of points; it starts at 1 and every sensing pose ``q_k``
multiplies it by ``1 − π(x, q_k)`` (eq. 9), so ``ι(x)`` is the probability that a target at ``x``
would still have been missed. The exploration component of a pose sequence is
``E = Σ_j ι(q_{k+j})``, the bonus at each position of the sequence, interpolated multilinearly
(eq. 10). Refinement: the centre probabilities ``T = Σ_j Σ_i π(x̂_i, q_{k+j})`` (eq. 11), or the
MI between the targets and the event "every measurement along the horizon is empty".
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from searchtrack.core.checks import positive
from searchtrack.core.errors import InvalidInputError
from searchtrack.core.intervals import interval_count
from searchtrack.core.types import FloatArray
from searchtrack.models.footprint import detection_matrix
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.plan.assign.mutual_info import binary_mi


@dataclass(frozen=True, eq=False)
class ExplorationBonus:
    """The grid ``ι`` of eq. (9) over an axis-aligned box (2-D or 3-D); immutable:
    :meth:`updated` returns the bonus after one more sensing pose.

    Parameters
    ----------
    bounds
        ``(d, 2)`` box ``[[x0, x1], [y0, y1](, [z0, z1])]`` in metres.
    resolution_m
        Largest grid spacing (004 does not give one; 10 m in this library's experiments).
        Each axis ``[lo, hi]`` is cut into ``n = ⌈(hi − lo) / resolution_m⌉`` equal cells
        (at least one; :func:`searchtrack.core.intervals.interval_count`, so floating-point
        round-off in the division never adds a cell): ``n + 1`` points, spacing
        ``(hi − lo) / n ≤ resolution_m``.
    """

    bounds: FloatArray
    resolution_m: float
    values: FloatArray = field(init=False, repr=False)
    axes: tuple[FloatArray, ...] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        b = np.array(self.bounds, dtype=np.float64)
        if b.ndim != 2 or b.shape[0] not in (2, 3) or b.shape[1] != 2 or not np.all(
                np.isfinite(b)) or np.any(b[:, 1] <= b[:, 0]):
            raise InvalidInputError("bounds", self.bounds, "must be (2|3, 2) with lo < hi")
        positive("resolution_m", self.resolution_m)
        b.setflags(write=False)
        axes = tuple(np.linspace(lo, hi, interval_count(hi - lo, self.resolution_m) + 1)
                     for lo, hi in b)
        values = np.ones(tuple(a.size for a in axes))
        values.setflags(write=False)
        object.__setattr__(self, "bounds", b)
        object.__setattr__(self, "axes", axes)
        object.__setattr__(self, "values", values)

    @cached_property
    def points(self) -> FloatArray:
        """``(G, d)`` grid points in C order of ``values``."""
        mesh = np.meshgrid(*self.axes, indexing="ij")
        return np.stack([m.reshape(-1) for m in mesh], axis=1)

    def updated(self, sensor: DetectionSensor, pose: FloatArray) -> ExplorationBonus:
        """Eq. (9): the bonus ``ι (1 − π(x, q))`` after sensing at ``pose``."""
        pts = self.points
        if pts.shape[1] == 2:
            pts = np.concatenate([pts, np.zeros((len(pts), 1))], 1)
        pd = detection_matrix(sensor, np.asarray(pose, dtype=np.float64)[None, :], pts)[0]
        values = self.values * (1.0 - pd.reshape(self.values.shape))
        values.setflags(write=False)
        out = copy.copy(self)
        object.__setattr__(out, "values", values)
        return out

    def at(self, positions: FloatArray) -> FloatArray:
        """``ι`` at ``(K, ≥d)`` positions, multilinear, clamped to the box."""
        d = len(self.axes)
        p = np.clip(np.asarray(positions, dtype=np.float64)[:, :d], self.bounds[:, 0],
                    self.bounds[:, 1])
        interp = RegularGridInterpolator(self.axes, self.values, method="linear")
        out: FloatArray = interp(p)
        return out


def exploration_value(bonus: ExplorationBonus, sequence: FloatArray) -> float:
    """Eq. (10): ``Σ_j ι(q_{k+j})`` over the ``(τ, ≥3)`` pose sequence."""
    return float(np.sum(bonus.at(sequence)))


def centre_probability(sensor: DetectionSensor, centres: FloatArray,
                       sequence: FloatArray) -> float:
    """Eq. (11): ``Σ_j Σ_i π(x̂_i, q_{k+j})`` (unweighted by cluster mass, as printed)."""
    if centres.shape[0] == 0:
        return 0.0
    return float(np.sum(detection_matrix(sensor, sequence, centres)))


def empty_horizon_mi(sensor: DetectionSensor, positions: FloatArray, weights: FloatArray,
                     sequence: FloatArray) -> float:
    """MI between the targets and ``e = 1{every measurement along the horizon is empty}``: the
    binary MI (paper 003 §2.5) of one measurement with ``p_d = 1 − Π_j (1 − π_j)``."""
    if positions.shape[0] == 0:
        return 0.0
    pd = detection_matrix(sensor, sequence, positions)
    seen = 1.0 - np.prod(1.0 - pd, axis=0)
    return binary_mi(seen[None, :], weights)
