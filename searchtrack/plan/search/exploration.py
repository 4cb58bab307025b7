"""The exploration bonus and the refinement terms of paper 004 (§4.1, eqs. 9–11).

The bonus ``ι`` lives on a grid of points; it starts at 1 and every sensing pose ``q_k``
multiplies it by ``1 − π(x, q_k)`` (eq. 9), so ``ι(x)`` is the probability that a target at ``x``
would still have been missed. The exploration component of a pose sequence is
``E = Σ_j ι(q_{k+j})`` with ``ι`` interpolated multilinearly (eq. 10 as corrected in digest 004,
ambiguity A2). Refinement: the centre probabilities ``T = Σ_j Σ_i π(x̂_i, q_{k+j})`` (eq. 11), or
the MI between the targets and the event "every measurement along the horizon is empty".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import RegularGridInterpolator

from searchtrack.core.errors import InvalidInputError
from searchtrack.core.types import FloatArray
from searchtrack.models.particle_models import DetectionSensor
from searchtrack.plan.assign.mutual_info import binary_mi
from searchtrack.plan.assign.problem import detection_matrix


@dataclass
class ExplorationBonus:
    """The grid ``ι`` of eq. (9) over an axis-aligned box (2-D or 3-D).

    Parameters
    ----------
    bounds
        ``(d, 2)`` box ``[[x0, x1], [y0, y1](, [z0, z1])]`` in metres.
    resolution_m
        Grid spacing (the paper leaves it open, ambiguity A8).
    """

    bounds: FloatArray
    resolution_m: float
    values: FloatArray = field(init=False)
    axes: tuple[FloatArray, ...] = field(init=False)

    def __post_init__(self) -> None:
        b = np.asarray(self.bounds, dtype=np.float64)
        if b.ndim != 2 or b.shape[0] not in (2, 3) or b.shape[1] != 2 or not np.all(
                np.isfinite(b)) or np.any(b[:, 1] <= b[:, 0]):
            raise InvalidInputError("bounds", self.bounds, "must be (2|3, 2) with lo < hi")
        if not (math.isfinite(self.resolution_m) and self.resolution_m > 0.0):
            raise InvalidInputError("resolution_m", self.resolution_m, "must be finite and > 0")
        self.bounds = b
        self.axes = tuple(np.linspace(lo, hi, max(2, math.ceil((hi - lo) / self.resolution_m)
                                                  + 1)) for lo, hi in b)
        self.values = np.ones(tuple(a.size for a in self.axes))

    @property
    def points(self) -> FloatArray:
        """``(G, d)`` grid points in C order of ``values``."""
        mesh = np.meshgrid(*self.axes, indexing="ij")
        return np.stack([m.reshape(-1) for m in mesh], axis=1)

    def update(self, sensor: DetectionSensor, pose: FloatArray) -> None:
        """Eq. (9): ``ι ← ι (1 − π(x, q))`` for one sensing pose."""
        pts = self._as_3d(self.points)
        pd = detection_matrix(sensor, np.asarray(pose, dtype=np.float64)[None, :], pts)[0]
        self.values = self.values * (1.0 - pd.reshape(self.values.shape))

    def at(self, positions: FloatArray) -> FloatArray:
        """``ι`` at ``(K, ≥d)`` positions, multilinear, clamped to the box."""
        d = len(self.axes)
        p = np.clip(np.asarray(positions, dtype=np.float64)[:, :d], self.bounds[:, 0],
                    self.bounds[:, 1])
        interp = RegularGridInterpolator(self.axes, self.values, method="linear")
        out: FloatArray = interp(p)
        return out

    def _as_3d(self, pts: FloatArray) -> FloatArray:
        return pts if pts.shape[1] == 3 else np.concatenate([pts, np.zeros((len(pts), 1))], 1)


def exploration_value(bonus: ExplorationBonus, sequence: FloatArray) -> float:
    """Eq. (10) as corrected: ``Σ_j ι(q_{k+j})`` over the ``(τ, ≥3)`` pose sequence."""
    return float(np.sum(bonus.at(sequence)))


def centre_probability(sensor: DetectionSensor, centres: FloatArray,
                       sequence: FloatArray) -> float:
    """Eq. (11): ``Σ_j Σ_i π(x̂_i, q_{k+j})`` (unweighted by cluster mass, as printed)."""
    if centres.shape[0] == 0:
        return 0.0
    return float(np.sum(detection_matrix(sensor, sequence, centres)))


def empty_horizon_mi(sensor: DetectionSensor, positions: FloatArray, weights: FloatArray,
                     sequence: FloatArray) -> float:
    """MI between the targets and ``e = 1{every measurement along the horizon is empty}``
    (digest 004 §2.5(a)): binary MI of one measurement with ``p_d = 1 − Π_j (1 − π_j)``."""
    if positions.shape[0] == 0:
        return 0.0
    pd = detection_matrix(sensor, sequence, positions)
    seen = 1.0 - np.prod(1.0 - pd, axis=0)
    return binary_mi(seen[None, :], weights)
